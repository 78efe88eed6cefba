#include "ray_shares.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <initializer_list>

#include "cpu_kernel.h"

namespace camhead::renderer::cpu {
namespace {

// The standard deviation of pixel i's samples' composite luminance (aux.z
// and aux.w hold its sum and sum of squares); 0 below two samples.
float luminance_sigma(std::span<const glm::vec4> aux, std::span<const std::uint32_t> counts,
                      std::size_t i) {
  const float n = float(counts[i]);
  if (n < 2.0f)
    return 0.0f;
  const float mean = aux[i].z / n;
  const float variance = (aux[i].w / n - mean * mean) * n / (n - 1.0f);
  return std::sqrt(std::max(variance, 0.0f));
}

} // namespace

std::uint64_t share_rays_by_noise(std::span<const PixelSpan> spans, int width, int height,
                                  std::span<const glm::vec4> aux,
                                  std::span<const std::uint32_t> counts,
                                  std::span<const std::uint32_t> own, std::uint32_t rpp,
                                  std::uint32_t most, std::uint32_t pattern_room,
                                  std::uint32_t frame_index, const RayShareBuffers &buffers,
                                  WorkerPool &pool) {
  const auto at = [width](std::uint32_t y, std::uint32_t x) {
    return std::size_t(y) * std::size_t(width) + x;
  };
  std::uint64_t pixels = 0;
  for (const PixelSpan &span : spans)
    pixels += span.x1 - span.x0;
  CpuKernel hasher; // for sampling.glsl's hash_u32
  std::uint64_t rays = 0;
  auto own_sigma = [&](int k) {
    const PixelSpan &span = spans[std::size_t(k)];
    for (std::size_t i = at(span.y, span.x0); i < at(span.y, span.x1); ++i)
      buffers.sigma[i] = luminance_sigma(aux, counts, i);
  };
  pool.run(int(spans.size()), own_sigma);
  double noise_sum = 0.0;
  double samples_sum = 0.0;
  for (const PixelSpan &span : spans)
    for (std::uint32_t x = span.x0; x < span.x1; ++x) {
      float sigma = 0.0f;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = int(x) + dx, ny = int(span.y) + dy;
          if (nx < 0 || ny < 0 || nx >= width || ny >= height)
            continue;
          const std::size_t j = at(std::uint32_t(ny), std::uint32_t(nx));
          if (counts[j] > 0) // traced this frame: sigma is its own
            sigma = std::max(sigma, buffers.sigma[j]);
        }
      const std::size_t i = at(span.y, x);
      const float n = float(counts[i]);
      const float noise = sigma + kNoiseFloor * std::abs(aux[i].z / n) + kNoiseFloor;
      // A sample of inf or NaN must not take every other pixel's rays.
      buffers.noise[i] = std::isfinite(noise) ? noise : kNoiseFloor;
      noise_sum += buffers.noise[i];
      samples_sum += n;
    }
  // Each pixel's way to its share of the rays after this frame (noise
  // holds it from here on).
  const double after = samples_sum + double(pixels) * rpp;
  double lack_sum = 0.0;
  for (const PixelSpan &span : spans)
    for (std::size_t i = at(span.y, span.x0); i < at(span.y, span.x1); ++i) {
      const double lack = std::max(0.0, after * buffers.noise[i] / noise_sum - counts[i]);
      buffers.noise[i] = float(lack);
      lack_sum += lack;
    }
  const double scale = lack_sum > 0.0 ? double(pixels) * rpp / lack_sum : 0.0;
  // A pixel's most rays a frame; in 64 bits, as a budget of 2^28 rays a
  // pixel would wrap 32.
  const double most_a_frame = double(kMostRaysAPixel) * double(rpp);
  const auto room = [](std::uint32_t limit, std::uint32_t used) {
    return limit > used ? limit - used : 0u; // moved samples may pass a limit
  };
  for (const PixelSpan &span : spans)
    for (std::size_t i = at(span.y, span.x0); i < at(span.y, span.x1); ++i) {
      // Rounded up or down at random (a hash of the pixel and the frame),
      // so that the shares add up to the budget on average.
      const double want = std::min(double(buffers.noise[i]) * scale, most_a_frame);
      const double whole = std::floor(want);
      const double u = double(hasher.hash_u32(std::uint32_t(i) * 0x9e3779b9u ^ frame_index)) *
                       (1.0 / 4294967296.0);
      const std::uint32_t k = std::uint32_t(whole) + (u < want - whole ? 1u : 0u);
      buffers.shares[i] = std::min({k, room(most, counts[i]), room(pattern_room, own[i])});
      rays += buffers.shares[i];
    }
  return rays;
}

} // namespace camhead::renderer::cpu
