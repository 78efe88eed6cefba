#version 450
// Adaptive allocation, step 2 of 5 (adaptive.glsl): the floor weight from the
// tiles' luminance, and the water level lambda by bisection on the histogram.
// One workgroup; every invocation takes every ADAPTIVE_SOLVE_THREADS-th bin.
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "adaptive.glsl"

#define ADAPTIVE_SOLVE_THREADS 256u
#define BINS_PER_THREAD (ADAPTIVE_BINS / ADAPTIVE_SOLVE_THREADS)

layout(local_size_x = ADAPTIVE_SOLVE_THREADS) in;

shared float partial[ADAPTIVE_SOLVE_THREADS];

// The sum of `value` over the workgroup, returned to every invocation.
float workgroup_sum(float value) {
  uint t = gl_LocalInvocationIndex;
  partial[t] = value;
  barrier();
  for (uint stride = ADAPTIVE_SOLVE_THREADS / 2u; stride > 0u; stride /= 2u) {
    if (t < stride) {
      partial[t] += partial[t + stride];
    }
    barrier();
  }
  float sum = partial[0];
  barrier(); // before the next call overwrites partial[]
  return sum;
}

void main() {
  uint t = gl_LocalInvocationIndex;
  uint tiles_x = (frame.image.x + CAMHEAD_TILE_X - 1u) / CAMHEAD_TILE_X;
  uint tiles = tiles_x * ((frame.image.y + CAMHEAD_TILE_Y - 1u) / CAMHEAD_TILE_Y);
  float luminance = 0.0f;
  for (uint g = t; g < tiles; g += ADAPTIVE_SOLVE_THREADS) {
    luminance += adaptive_groups[g];
  }
  float pixels = adaptive_pixels();
  float floor_weight =
      ADAPTIVE_FLOOR_FRACTION * workgroup_sum(luminance) / pixels + ADAPTIVE_FLOOR_ABSOLUTE;

  float mean_weight[BINS_PER_THREAD];
  uint count[BINS_PER_THREAD];
  for (uint j = 0u; j < BINS_PER_THREAD; ++j) {
    uint bin = t + j * ADAPTIVE_SOLVE_THREADS;
    count[j] = adaptive_histogram[2u * bin];
    mean_weight[j] =
        count[j] > 0u ? adaptive_bin_mean(bin, count[j], adaptive_histogram[2u * bin + 1u]) : 0.0f;
  }
  float pilot = float(frame.tracing.y);
  float cap = frame.adaptive.y;
  float budget = pixels * float(frame.sampling.z);
  float low = -ADAPTIVE_LOG2_LAMBDA_RANGE;
  float high = ADAPTIVE_LOG2_LAMBDA_RANGE;
  for (int step = 0; step < ADAPTIVE_BISECTION_STEPS; ++step) {
    float middle = 0.5f * (low + high);
    float lambda = exp2(middle);
    float total = 0.0f;
    for (uint j = 0u; j < BINS_PER_THREAD; ++j) {
      total += adaptive_bin_total(mean_weight[j], count[j], lambda, floor_weight, pilot, cap);
    }
    // The same sum in every invocation, so the branch is uniform.
    if (workgroup_sum(total) < budget) {
      low = middle;
    } else {
      high = middle;
    }
  }
  float lambda = exp2(high);
  float expected = 0.0f;
  for (uint j = 0u; j < BINS_PER_THREAD; ++j) {
    expected += adaptive_bin_total(mean_weight[j], count[j], lambda, floor_weight, pilot, cap);
  }
  expected = workgroup_sum(expected);
  if (t == 0u) {
    adaptive_solution.solution = vec4(lambda, floor_weight, expected, 0.0f);
    adaptive_solution.rays = uvec4(0u);
  }
}
