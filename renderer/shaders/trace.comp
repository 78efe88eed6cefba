#version 450
// Adds a batch of samples per pixel to the accumulators (kernel.glsl).
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "kernel.glsl"

layout(local_size_x = CAMHEAD_TILE_X, local_size_y = CAMHEAD_TILE_Y) in;

void main() {
  int i = pixel_index();
  if (i < 0) {
    return;
  }
  // An adaptive second pass dispatches every pixel for samples up to the
  // cap; a pixel whose share is done skips the accumulators' round trip.
  if (frame.tracing.y != 0u && sample_counts[i] - frame.tracing.y <= frame.sampling.x) {
    return;
  }
  vec4 acc_mixed = accum_mixed[i];
  vec4 acc_real = accum_real[i];
  vec4 acc_aux = accum_aux[i];
  bool has_plate = frame.image.z != 0u;
  vec4 camera = has_plate ? plate[i] : vec4(0.0f);
  trace_pixel(gl_GlobalInvocationID.x, gl_GlobalInvocationID.y, camera, has_plate, acc_mixed,
              acc_real, acc_aux);
  accum_mixed[i] = acc_mixed;
  accum_real[i] = acc_real;
  accum_aux[i] = acc_aux;
}
