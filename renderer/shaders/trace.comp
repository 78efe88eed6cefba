#version 450
// Adds a batch of samples per pixel to the accumulators (kernel.glsl).
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "kernel.glsl"
#include "sample_queue.glsl"

layout(local_size_x = CAMHEAD_TILE_X, local_size_y = CAMHEAD_TILE_Y) in;

// The adaptive second pass takes its pixels from the queue, one a lane
// (sample_queue.glsl); every other pass, the pixel under the invocation.
layout(constant_id = 1) const bool FROM_QUEUE = false;

void main() {
  uint x;
  uint y;
  int i;
  if (FROM_QUEUE) {
    i = queue_pixel(frame.sampling.x);
    if (i < 0) {
      return;
    }
    x = uint(i) % frame.image.x;
    y = uint(i) / frame.image.x;
  } else {
    uvec2 p;
    i = pixel_index(p);
    if (i < 0) {
      return;
    }
    x = p.x;
    y = p.y;
  }
  // In the adaptive second pass, a pixel whose share is done skips the
  // accumulators' round trip (bins wider than one share hold some).
  if (frame.tracing.y != 0u && sample_counts[i] - frame.tracing.y <= frame.sampling.x) {
    return;
  }
  // A frame's first batch writes the accumulators instead of adding to what
  // they hold, so the host need not clear three whole layers before it
  // (layout.h, "The trace kernel adds").
  bool first_batch = frame.sampling.x == 0u && frame.tracing.y == 0u;
  vec4 acc_mixed = first_batch ? vec4(0.0f) : imageLoad(accum_mixed, i);
  vec4 acc_real = first_batch ? vec4(0.0f) : imageLoad(accum_real, i);
  vec4 acc_aux = first_batch ? vec4(0.0f) : imageLoad(accum_aux, i);
  bool has_plate = frame.image.z != 0u;
  vec4 camera = has_plate ? imageLoad(plate, i) : vec4(0.0f);
  trace_pixel(x, y, camera, has_plate, acc_mixed, acc_real, acc_aux);
  imageStore(accum_mixed, i, acc_mixed);
  imageStore(accum_real, i, acc_real);
  imageStore(accum_aux, i, acc_aux);
}
