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

// The pixel's Gaussian: at most half the widest reach, so that it is cut at
// 2 sigma (and a hit at depth 0, an infinite blur, is bounded).
float reconstruct_sigma(vec4 pixel) {
  return min(frame.reconstruct.x * sqrt(abs(pixel.x)) / pow(max(pixel.y, 1.0f), 1.0f / 3.0f),
             0.5f * frame.reconstruct.z);
}

int reconstruct_reach(float sigma) {
  return int(min(ceil(2.0f * sigma), frame.reconstruct.z));
}

// Whether neighbour `other` may lend its samples to `pixel`: a traced pixel
// whose blur differs by no more than the larger of the two (or a pixel).
bool reconstruct_alike(vec4 pixel, vec4 other) {
  float b = pixel.x;
  float c = other.x;
  return other.y > 0.0f && abs(c - b) <= max(max(1.0f, abs(b)), abs(c));
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
  int reach = reconstruct_reach(sigma);
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
