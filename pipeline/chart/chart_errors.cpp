// See chart_errors.h.
#include "chart/chart_errors.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace camhead::cli {

using renderer::Image;

double relative_rmse(const Image &reference, const Image &test,
                     const std::vector<std::uint8_t> &mask) {
  if (reference.width != test.width || reference.height != test.height ||
      reference.channels != test.channels)
    throw std::runtime_error("image sizes differ: " + std::to_string(reference.width) + "x" +
                             std::to_string(reference.height) + " vs " +
                             std::to_string(test.width) + "x" + std::to_string(test.height));
  double diff = 0.0, ref = 0.0;
  const int ch = reference.channels;
  for (std::size_t i = 0; i < reference.pixel_count(); ++i) {
    if (!mask.empty() && mask[i] == 0)
      continue;
    for (int c = 0; c < ch; ++c) {
      const double a = reference.data[i * ch + c], b = test.data[i * ch + c];
      diff += (a - b) * (a - b);
      ref += a * a;
    }
  }
  return ref > 0.0 ? std::sqrt(diff / ref) : std::numeric_limits<double>::quiet_NaN();
}

std::vector<std::uint8_t> depth_edge_mask(const Image &depth, int radius) {
  const int w = depth.width, h = depth.height;
  const auto z = [&](int x, int y) { return depth.data[std::size_t(y) * w + x]; };
  std::vector<std::uint8_t> edge(std::size_t(w) * h, 0);
  const auto step = [&](int x, int y, int dx, int dy) -> double {
    const int x1 = x + dx, y1 = y + dy;
    if (x < 0 || y < 0 || x1 < 0 || y1 < 0 || x1 >= w || y1 >= h || x >= w || y >= h)
      return 0.0;
    const float a = z(x, y), b = z(x1, y1);
    if (a <= 0.0f || b <= 0.0f)
      return 0.0;
    return std::abs(double(a) - b);
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (const auto &[dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const int x1 = x + dx, y1 = y + dy;
        if (x1 >= w || y1 >= h)
          continue;
        const float a = z(x, y), b = z(x1, y1);
        bool is_edge = (a > 0.0f) != (b > 0.0f);
        if (a > 0.0f && b > 0.0f) {
          const double jump = std::abs(double(a) - b);
          const double around = std::max(step(x - dx, y - dy, dx, dy), step(x1, y1, dx, dy));
          is_edge = jump > 0.05 * std::min(a, b) && jump > 3.0 * around;
        }
        if (is_edge) {
          edge[std::size_t(y) * w + x] = 1;
          edge[std::size_t(y1) * w + x1] = 1;
        }
      }
  std::vector<std::uint8_t> mask(edge.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (edge[std::size_t(y) * w + x] == 0)
        continue;
      for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx) {
          const int mx = x + dx, my = y + dy;
          if (mx >= 0 && my >= 0 && mx < w && my < h && dx * dx + dy * dy <= radius * radius)
            mask[std::size_t(my) * w + mx] = 1;
        }
    }
  return mask;
}

Image box_downsample(const Image &image, int k) {
  if (k == 1)
    return image;
  Image out(image.width / k, image.height / k, image.channels);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < image.channels; ++c) {
        double sum = 0.0;
        for (int j = 0; j < k; ++j)
          for (int i = 0; i < k; ++i)
            sum += image.at(x * k + i, y * k + j)[c];
        out.at(x, y)[c] = float(sum / (k * k));
      }
  return out;
}

} // namespace camhead::cli
