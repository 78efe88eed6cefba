#version 450
// Adaptive allocation, step 5 of 5 (sample_queue.glsl): each pixel with
// samples left after the pilot into its bin's part of the queue. The order
// inside a bin follows the atomics; each pixel's samples are traced by one
// invocation in their own order, so the image does not depend on it.
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "sample_queue.glsl"

layout(local_size_x = CAMHEAD_TILE_X, local_size_y = CAMHEAD_TILE_Y) in;

void main() {
  uvec2 p;
  int i = pixel_index(p);
  if (i < 0) {
    return;
  }
  uint samples = sample_counts[i];
  uint pilot = frame.tracing.y;
  if (samples > pilot) {
    uint place = atomicAdd(queue_bins[QUEUE_COUNTS + queue_bin(samples - pilot)], 1u);
    sample_queue[place] = uint(i);
  }
}
