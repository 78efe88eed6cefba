#version 450
// The reconstruction's first two passes over the traced pixels
// (reconstruct.glsl): each pixel's blur and samples, then the rows' sums.
#extension GL_GOOGLE_include_directive : require
#include "buffers.glsl"
#include "reconstruct.glsl"

layout(local_size_x = CAMHEAD_TILE_X, local_size_y = CAMHEAD_TILE_Y) in;

layout(constant_id = 1) const uint RECONSTRUCT_PASS = 0u;

void main() {
  uvec2 p;
  int i = pixel_index(p);
  if (i < 0) {
    return;
  }
  if (RECONSTRUCT_PASS == 0u) {
    // The signed blur radius at the pixel's mean depth (a miss: at
    // infinity), and the samples the accumulators hold (the last batch's end).
    float blur = reconstruct_blur(imageLoad(accum_aux, i), frame.lens.x * frame.lens.z,
                                  1.0f / frame.lens.y);
    imageStore(filter_pixels, i, vec4(blur, float(frame.sampling.y), 0.0f, 0.0f));
    return;
  }
  vec4 pixel = imageLoad(filter_pixels, i);
  vec4 m = imageLoad(accum_mixed, i);
  vec4 r = vec4(imageLoad(accum_real, i).xyz, pixel.y);
  float sigma = reconstruct_sigma(pixel);
  if (sigma >= frame.reconstruct.y) {
    reconstruct_gather(i, pixel, sigma, int(p.x), int(frame.image.x), 1, false, m, r);
  }
  imageStore(filter_rows_mixed, i, m);
  imageStore(filter_rows_real, i, r);
}
