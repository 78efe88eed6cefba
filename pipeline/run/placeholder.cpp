#include "placeholder.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace camhead::pipeline {

void fill_placeholder(const base::VideoFormat &f, std::span<std::uint8_t> out) {
  const std::size_t stride = base::row_bytes(f);
  const auto grey = [&](int y) { return std::abs(y - f.height / 2) < f.height / 10 ? 0.3 : 0.5; };
  for (int y = 0; y < f.height; ++y) {
    std::uint8_t *row = out.data() + stride * std::size_t(y);
    const double g = grey(y);
    switch (f.pixel) {
    case base::PixelFormat::yuyv:
      for (int x = 0; x < f.width; x += 2) {
        const auto luma = std::uint8_t(std::lround(16 + 219 * g));
        row[2 * x] = row[2 * x + 2] = luma;
        row[2 * x + 1] = row[2 * x + 3] = 128;
      }
      break;
    case base::PixelFormat::nv12:
      std::fill_n(row, f.width, std::uint8_t(std::lround(16 + 219 * g)));
      break;
    case base::PixelFormat::rgb24:
    case base::PixelFormat::bgr24:
      std::fill_n(row, 3 * std::size_t(f.width), std::uint8_t(std::lround(255 * g)));
      break;
    case base::PixelFormat::xrgb8888:
      for (int x = 0; x < f.width; ++x) {
        std::fill_n(row + 4 * std::size_t(x), 3, std::uint8_t(std::lround(255 * g)));
        row[4 * std::size_t(x) + 3] = 0xff;
      }
      break;
    }
  }
  if (f.pixel == base::PixelFormat::nv12)
    std::fill(out.begin() + std::ptrdiff_t(stride * std::size_t(f.height)),
              out.begin() + std::ptrdiff_t(base::frame_bytes(f)), std::uint8_t(128));
}

} // namespace camhead::pipeline
