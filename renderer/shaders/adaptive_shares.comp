#version 450
// Adaptive allocation, step 3 of 3 (adaptive.glsl): each pixel's share into
// sample_counts, and the 64-bit total of the shares.
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "adaptive.glsl"

layout(local_size_x = CAMHEAD_TILE_X, local_size_y = CAMHEAD_TILE_Y) in;

const uint kTilePixels = CAMHEAD_TILE_X * CAMHEAD_TILE_Y;
shared uint tile_samples[kTilePixels];

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  uint samples = 0u;
  if (p.x < frame.image.x && p.y < frame.image.y) {
    uint i = p.y * frame.image.x + p.x;
    vec4 solution = adaptive_solution.solution;
    samples = adaptive_share(adaptive_weights[i], i, solution.x, solution.y,
                             float(frame.tracing.y), frame.adaptive.y);
    sample_counts[i] = samples;
  }
  uint t = gl_LocalInvocationIndex;
  tile_samples[t] = samples;
  barrier();
  for (uint stride = kTilePixels / 2u; stride > 0u; stride /= 2u) {
    if (t < stride) {
      tile_samples[t] += tile_samples[t + stride];
    }
    barrier();
  }
  if (t == 0u) {
    uint before = atomicAdd(adaptive_solution.rays.x, tile_samples[0]);
    if (before + tile_samples[0] < before) { // the low word wrapped
      atomicAdd(adaptive_solution.rays.y, 1u);
    }
  }
}
