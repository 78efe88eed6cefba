#include "luma.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace camhead::pipeline {

void copy_luma(const base::VideoFormat &format, std::span<const std::uint8_t> frame,
               std::span<std::uint8_t> out) {
  const std::size_t w = std::size_t(format.width), stride = base::row_bytes(format);
  for (std::size_t y = 0; y < std::size_t(format.height); ++y) {
    const std::uint8_t *row = frame.data() + y * stride;
    std::uint8_t *dst = out.data() + y * w;
    switch (format.pixel) {
    case base::PixelFormat::nv12:
      std::memcpy(dst, row, w);
      break;
    case base::PixelFormat::yuyv:
      for (std::size_t x = 0; x < w; ++x)
        dst[x] = row[2 * x];
      break;
    case base::PixelFormat::rgb24:
    case base::PixelFormat::bgr24:
    case base::PixelFormat::xrgb8888: {
      // Red, green and blue at these offsets within a pixel of `step` bytes
      // (xrgb8888 is B, G, R, X in memory).
      const bool rgb = format.pixel == base::PixelFormat::rgb24;
      const std::size_t step = format.pixel == base::PixelFormat::xrgb8888 ? 4 : 3;
      const std::size_t r = rgb ? 0 : 2, b = rgb ? 2 : 0;
      for (std::size_t x = 0; x < w; ++x) {
        const std::uint8_t *p = row + step * x;
        dst[x] = std::uint8_t((77u * p[r] + 150u * p[1] + 29u * p[b] + 128u) >> 8);
      }
      break;
    }
    }
  }
}

bool luma_limited_range(const base::VideoFormat &format) {
  return base::is_yuv(format.pixel) && format.range == base::ColorRange::limited;
}

void luma_to_full_range(std::span<std::uint8_t> luma) {
  for (std::uint8_t &code : luma)
    code = std::uint8_t(std::clamp(int(std::lround((code - 16) * 255.0 / 219.0)), 0, 255));
}

} // namespace camhead::pipeline
