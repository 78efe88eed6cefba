#version 450
// Adaptive allocation, step 3 of 5 (adaptive.glsl): each pixel's share into
// sample_counts, the 64-bit total of the shares, and the pixels with samples
// left after the pilot counted by bin of their share (sample_queue.glsl).
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "adaptive.glsl"
#include "sample_queue.glsl"

layout(local_size_x = CAMHEAD_TILE_X, local_size_y = CAMHEAD_TILE_Y) in;

const uint kTilePixels = CAMHEAD_TILE_X * CAMHEAD_TILE_Y;
shared uint tile_samples[kTilePixels];

void main() {
  uvec3 id;
  if (!grid_invocation(GROUP_LIST_TILES, uvec2(CAMHEAD_TILE_X, CAMHEAD_TILE_Y), id)) {
    return; // the whole workgroup
  }
  uvec2 p = id.xy;
  uint samples = 0u;
  if (p.x < frame.image.x && p.y < frame.image.y) {
    uint i = p.y * frame.image.x + p.x;
    vec4 solution = adaptive_solution.solution;
    samples = adaptive_share(adaptive_weights[i], i, solution.x, solution.y,
                             float(frame.tracing.y), frame.adaptive.y);
    sample_counts[i] = samples;
    uint pilot = frame.tracing.y;
    if (samples > pilot) {
      atomicAdd(queue_bins[QUEUE_COUNTS + queue_bin(samples - pilot)], 1u);
    }
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
