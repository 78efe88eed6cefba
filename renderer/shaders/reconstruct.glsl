// A live frame's reconstruction on the GPU: the CPU reference's
// (renderer/src/defocus_filter.h says what it is and why), step for step in
// float. Each traced pixel's layers become the sample-weighted mean of its
// neighbours' within a Gaussian of sigma = strength sqrt(|c|) / n^(1/3)
// pixels (c its signed blur radius, n its samples), among neighbours of alike
// blur, rows then columns:
//   reconstruct.comp, RECONSTRUCT_PASS 0: each pixel's blur and samples;
//                     RECONSTRUCT_PASS 1: the rows' weighted sums;
//   resolve.comp with RESOLVE_FILTERED: the columns' sums, their means and
//                     the composite from them.
// Only traced pixels take part (BINDING_FILTER_PIXELS.y > 0: the host
// clears it where a history starts or the frame before did not
// reconstruct, and the first pass writes it over the region), and only the
// layers are filtered, never the camera image.
// Needs buffers.glsl first.

layout(binding = BINDING_FILTER_PIXELS, rgba32f) uniform restrict imageBuffer filter_pixels;
layout(binding = BINDING_FILTER_ROWS_MIXED, rgba32f) uniform restrict imageBuffer filter_rows_mixed;
layout(binding = BINDING_FILTER_ROWS_REAL, rgba32f) uniform restrict imageBuffer filter_rows_real;

#define CUBE_ROOT(x) pow(x, 1.0f / 3.0f)
#include "reconstruct_rules.glsl"
#undef CUBE_ROOT

// A pixel's Gaussian (filter_pixels: its blur radius and samples), with
// the frame's strength and widest reach.
float reconstruct_sigma(vec4 pixel) {
  return reconstruct_sigma_of(pixel.x, pixel.y, frame.reconstruct.x, frame.reconstruct.z);
}

// Whether neighbour `other` may lend its samples to `pixel`: a traced pixel
// of alike blur.
bool reconstruct_alike(vec4 pixel, vec4 other) {
  return other.y > 0.0f && reconstruct_blurs_alike(pixel.x, other.x);
}

// The neighbours at +-1 .. +-reach steps of `step` pixels (`along` the
// pixel's coordinate on that axis, `size` the axis's length) added with
// Gaussian weights into `m`, `r` (the weight in r.w): from the accumulators
// (the rows, `from_rows` false) or from the rows' sums (the columns, whose
// weights are in the rows' real .w). exp(f (k+1)^2) = exp(f k^2) exp(f (2k + 1)).
void reconstruct_gather(int i, vec4 pixel, float sigma, int along, int size, int step,
                        bool from_rows, inout vec4 m, inout vec4 r) {
  float falloff = -0.5f / (sigma * sigma);
  float w = exp(falloff);
  float ratio = exp(3.0f * falloff);
  float ratio_step = exp(2.0f * falloff);
  int reach = reconstruct_reach_of(sigma, frame.reconstruct.z);
  for (int k = 1; k <= reach; ++k) {
    for (int side = -1; side <= 1; side += 2) {
      int at = along + side * k;
      if (at < 0 || at >= size) {
        continue;
      }
      int j = i + side * k * step;
      vec4 other = imageLoad(filter_pixels, j);
      if (!reconstruct_alike(pixel, other)) {
        continue;
      }
      if (from_rows) {
        m += w * imageLoad(filter_rows_mixed, j);
        r += w * imageLoad(filter_rows_real, j);
      } else {
        m += w * imageLoad(accum_mixed, j);
        r += w * vec4(imageLoad(accum_real, j).xyz, other.y);
      }
    }
    w *= ratio;
    ratio *= ratio_step;
  }
}
