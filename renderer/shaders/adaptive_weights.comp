#version 450
// Adaptive allocation, step 1 of 5 (adaptive.glsl): each pixel's weight from
// the pilot, counted into the histogram, and each tile's sum of absolute mean
// luminance for the floor weight.
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "adaptive.glsl"

layout(local_size_x = CAMHEAD_TILE_X, local_size_y = CAMHEAD_TILE_Y) in;

const uint kTilePixels = CAMHEAD_TILE_X * CAMHEAD_TILE_Y;
shared float tile_luminance[kTilePixels];

void main() {
  uvec3 id;
  if (!grid_invocation(GROUP_LIST_TILES, uvec2(CAMHEAD_TILE_X, CAMHEAD_TILE_Y), id)) {
    return; // the whole workgroup
  }
  uvec2 p = id.xy;
  float luminance = 0.0f;
  // No other early return: every invocation reaches the barriers below.
  if (p.x < frame.image.x && p.y < frame.image.y) {
    uint i = p.y * frame.image.x + p.x;
    float w = adaptive_weight(int(p.x), int(p.y));
    adaptive_weights[i] = w;
    uint bin = adaptive_bin(w);
    atomicAdd(adaptive_histogram[2u * bin], 1u);
    atomicAdd(adaptive_histogram[2u * bin + 1u], adaptive_bin_offset(w));
    luminance = abs(adaptive_moments(accum_aux_at(i), float(frame.tracing.y)).x);
  }
  uint t = gl_LocalInvocationIndex;
  tile_luminance[t] = luminance;
  barrier();
  for (uint stride = kTilePixels / 2u; stride > 0u; stride /= 2u) {
    if (t < stride) {
      tile_luminance[t] += tile_luminance[t + stride];
    }
    barrier();
  }
  if (t == 0u) {
    // By the tile's place in the image: a region's dispatch covers part of it.
    uint tiles_x = (frame.image.x + CAMHEAD_TILE_X - 1u) / CAMHEAD_TILE_X;
    adaptive_groups[(p.y / CAMHEAD_TILE_Y) * tiles_x + p.x / CAMHEAD_TILE_X] = tile_luminance[0];
  }
}
