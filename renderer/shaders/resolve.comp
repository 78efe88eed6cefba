#version 450
// Averages the accumulators into the layers and composites them (equation 4).
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "kernel.glsl"

void main() {
  int i = pixel_index();
  if (i < 0) {
    return;
  }
  bool has_plate = frame.image.z != 0u;
  vec4 camera = has_plate ? plate[i] : vec4(0.0f);
  Resolved r = resolve_pixel(accum_mixed[i], accum_real[i], accum_aux[i], camera, has_plate);
  out_composite[i] = vec4(r.composite, 1.0f);
  out_mixed[i] = vec4(r.mixed, 1.0f);
  out_real[i] = vec4(r.real, 1.0f);
  out_aux[i] = vec4(r.mask, r.depth, 0.0f, 0.0f);
}
