#include "camhead/renderer/adaptive.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace camhead::renderer {

std::uint32_t adaptive_pilot(const AdaptiveSampling &settings, std::uint32_t mean_samples) {
  const std::uint32_t quarter = std::max(1u, mean_samples / 4u);
  return std::max(1u, std::min({settings.pilot, mean_samples, quarter}));
}

std::vector<std::uint32_t> allocate_samples(std::span<const glm::vec4> pilot_aux,
                                            const gpu::FrameParams &frame, std::uint32_t pilot,
                                            const AdaptiveSampling &settings) {
  const int width = int(frame.image.x);
  const int height = int(frame.image.y);
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  const std::uint32_t mean_samples = std::max(frame.sampling.z, pilot);
  const double n = double(std::max(pilot, 1u));

  // Per pixel: the pilot's mean luminance and sample variance.
  std::vector<double> mean(pixels), variance(pixels);
  double image_mean = 0.0;
  for (std::size_t i = 0; i < pixels; ++i) {
    const glm::vec4 a = pilot_aux[i];
    mean[i] = double(a.z) / n;
    const double second = double(a.w) / n;
    variance[i] = n > 1.0 ? std::max(0.0, second - mean[i] * mean[i]) * n / (n - 1.0) : 0.0;
    image_mean += std::abs(mean[i]);
  }
  image_mean /= double(std::max<std::size_t>(pixels, 1));

  // Each pixel's weight, an estimate of the standard deviation of one of its
  // samples: the largest pilot variance in its 3x3 neighbourhood (a pilot of
  // a few samples misses edges that its neighbours catch), a quarter of the
  // variance of the neighbourhood's samples pooled (which alone sees
  // anything when the pilot is one sample), and a floor from the circle of
  // confusion.
  const double aperture = frame.lens.x;
  const double focus = frame.lens.y;
  const double focal_px = frame.lens.z;
  std::vector<double> weight(pixels);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double largest = 0.0, sum = 0.0, squares = 0.0, count = 0.0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= width || ny >= height)
            continue;
          const std::size_t j = std::size_t(ny) * width + nx;
          largest = std::max(largest, variance[j]);
          sum += pilot_aux[j].z;
          squares += pilot_aux[j].w;
          count += n;
        }
      const double pooled_mean = sum / count;
      const double pooled = std::max(0.0, squares / count - pooled_mean * pooled_mean);
      const std::size_t i = std::size_t(y) * width + x;
      const glm::vec4 a = pilot_aux[i];
      const double inverse_depth = a.y > 0.0f ? double(a.y) / double(a.x) : 0.0; // miss: infinity
      const double coc_px =
          aperture > 0.0 ? aperture * focal_px * std::abs(inverse_depth - 1.0 / focus) : 0.0;
      const double coc = settings.coc_weight * std::abs(mean[i]) * std::min(coc_px, 8.0) / 8.0;
      weight[i] = std::sqrt(largest + 0.25 * pooled + coc * coc) + 1e-3 * image_mean + 1e-12;
    }

  // Water-filling: n_i = clamp(lambda w_i, pilot, cap) with lambda such that
  // the n_i add up to the budget, which minimises sum sigma_i^2 / n_i.
  const double cap =
      std::max(double(pilot), std::floor(double(settings.max_factor) * mean_samples));
  const double budget = double(pixels) * mean_samples;
  const auto total_at = [&](double lambda) {
    double total = 0.0;
    for (std::size_t i = 0; i < pixels; ++i)
      total += std::clamp(lambda * weight[i], double(pilot), cap);
    return total;
  };
  double lo = 0.0, hi = 1.0;
  while (total_at(hi) < budget && hi < 1e30)
    hi *= 2.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (total_at(mid) < budget ? lo : hi) = mid;
  }
  std::vector<double> target(pixels);
  std::vector<std::uint32_t> counts(pixels);
  double assigned = 0.0;
  for (std::size_t i = 0; i < pixels; ++i) {
    target[i] = std::clamp(hi * weight[i], double(pilot), cap);
    counts[i] = std::uint32_t(std::floor(target[i]));
    assigned += counts[i];
  }
  // The rounding remainder, one sample each to the largest fractions.
  std::vector<std::size_t> order(pixels);
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const double fa = target[a] - std::floor(target[a]), fb = target[b] - std::floor(target[b]);
    return fa != fb ? fa > fb : a < b;
  });
  for (std::size_t k = 0; k < pixels && assigned < budget; ++k)
    if (counts[order[k]] < cap) {
      ++counts[order[k]];
      assigned += 1.0;
    }
  return counts;
}

} // namespace camhead::renderer
