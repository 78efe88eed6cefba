// The C++ executor of the adaptive allocation: the three GPU steps
// (adaptive_weights.comp, adaptive_solve.comp, adaptive_shares.comp) in the
// same order, with the same arithmetic (adaptive.glsl) and the same
// reduction trees, so that both executors give out the same shares.
#include "camhead/renderer/adaptive.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/integer.hpp>
#include <glm/vec2.hpp>

namespace camhead::renderer {

namespace cpu {
namespace {

using namespace glm; // the GLSL built-ins adaptive.glsl calls unqualified
using gpu::FrameParams;
using uint = std::uint32_t;

#define KERNEL_TABLE static constexpr // sampling.glsl's constant arrays, members

#ifndef CAMHEAD_PI
#define CAMHEAD_PI 3.14159265358979f
#endif

struct AdaptiveKernel {
  const vec4 *accum_aux = nullptr;
  FrameParams frame{};
  // The GLSL kernels read the layer through a texel buffer (buffers.glsl).
  [[nodiscard]] vec4 accum_aux_at(uint index) const { return accum_aux[index]; }

#include "adaptive.glsl"
};

constexpr uint kSolveThreads = 256; // adaptive_solve.comp's ADAPTIVE_SOLVE_THREADS
constexpr uint kTileX = CAMHEAD_TILE_X;
constexpr uint kTileY = CAMHEAD_TILE_Y;

// A workgroup's shared-memory tree sum, in the kernels' order.
template <std::size_t N> float tree_sum(std::array<float, N> values) {
  for (std::size_t stride = N / 2; stride > 0; stride /= 2)
    for (std::size_t t = 0; t < stride; ++t)
      values[t] += values[t + stride];
  return values[0];
}

} // namespace
} // namespace cpu

std::uint32_t adaptive_pilot(const AdaptiveSampling &settings, std::uint32_t mean_samples) {
  const std::uint32_t quarter = std::max(1u, mean_samples / 4u);
  return std::max(1u, std::min({settings.pilot, mean_samples, quarter}));
}

gpu::vec4 adaptive_parameters(const AdaptiveSampling &settings, std::uint32_t pilot,
                              std::uint32_t mean_samples) {
  const float cap = std::max(float(pilot), std::floor(settings.max_factor * float(mean_samples)));
  return {settings.coc_weight, cap, 0.0f, 0.0f};
}

std::vector<std::uint32_t> allocate_samples(std::span<const glm::vec4> pilot_aux,
                                            const gpu::FrameParams &frame, std::uint32_t pilot,
                                            const AdaptiveSampling &settings,
                                            const InfluenceRegion *region) {
  using cpu::kSolveThreads;
  using cpu::kTileX;
  using cpu::kTileY;
  cpu::AdaptiveKernel k;
  k.accum_aux = pilot_aux.data();
  k.frame = frame;
  k.frame.tracing.y = pilot;
  k.frame.sampling.z = std::max(frame.sampling.z, pilot);
  k.frame.adaptive = adaptive_parameters(settings, pilot, k.frame.sampling.z);
  const std::uint32_t width = frame.image.x;
  const std::uint32_t height = frame.image.y;
  const std::size_t pixels = std::size_t(width) * height;
  const InfluenceRegion everything = whole_frame_region(width, height);
  const InfluenceRegion &shared = region != nullptr ? *region : everything;
  if (region != nullptr)
    k.frame.adaptive.z = float(region->pixels());

  // 1. adaptive_weights.comp: weights, histogram, tile luminance, a tile
  //    (workgroup) at a time, over the region's tiles (the others stay 0).
  std::vector<float> weights(pixels, 0.0f);
  std::vector<std::uint32_t> histogram(2 * ADAPTIVE_BINS, 0u);
  const std::uint32_t tiles_x = (width + kTileX - 1) / kTileX;
  const std::uint32_t tiles_y = (height + kTileY - 1) / kTileY;
  std::vector<float> tiles(std::size_t(tiles_x) * tiles_y, 0.0f);
  for (const PixelRect &rect : shared.rects)
    for (std::uint32_t ty = rect.y0 / kTileY; ty * kTileY < rect.y1; ++ty)
      for (std::uint32_t tx = rect.x0 / kTileX; tx * kTileX < rect.x1; ++tx) {
        // By local invocation index, as the kernel's shared array.
        std::array<float, kTileX * kTileY> luminance{};
        for (std::uint32_t t = 0; t < kTileX * kTileY; ++t) {
          const std::uint32_t x = tx * kTileX + t % kTileX, y = ty * kTileY + t / kTileX;
          if (x >= width || y >= height)
            continue;
          const std::size_t i = std::size_t(y) * width + x;
          const float w = k.adaptive_weight(int(x), int(y));
          weights[i] = w;
          const std::uint32_t bin = k.adaptive_bin(w);
          histogram[2 * bin] += 1u;
          histogram[2 * bin + 1] += k.adaptive_bin_offset(w);
          luminance[t] = std::abs(k.adaptive_moments(pilot_aux[i], float(pilot)).x);
        }
        tiles[std::size_t(ty) * tiles_x + tx] = cpu::tree_sum(luminance);
      }

  // 2. adaptive_solve.comp: floor weight and water level.
  std::array<float, kSolveThreads> partial{};
  for (std::size_t g = 0; g < tiles.size(); ++g)
    partial[g % kSolveThreads] += tiles[g];
  const float sharing = k.adaptive_pixels();
  const float floor_weight =
      ADAPTIVE_FLOOR_FRACTION * cpu::tree_sum(partial) / sharing + ADAPTIVE_FLOOR_ABSOLUTE;
  std::vector<float> mean_weight(ADAPTIVE_BINS, 0.0f);
  for (std::uint32_t bin = 0; bin < ADAPTIVE_BINS; ++bin)
    if (histogram[2 * bin] > 0)
      mean_weight[bin] = k.adaptive_bin_mean(bin, histogram[2 * bin], histogram[2 * bin + 1]);
  const float pilot_f = float(pilot);
  const float cap = k.frame.adaptive.y;
  const auto total_at = [&](float lambda) {
    std::array<float, kSolveThreads> sums{};
    for (std::uint32_t bin = 0; bin < ADAPTIVE_BINS; ++bin)
      sums[bin % kSolveThreads] += k.adaptive_bin_total(mean_weight[bin], histogram[2 * bin],
                                                        lambda, floor_weight, pilot_f, cap);
    return cpu::tree_sum(sums);
  };
  const float budget = sharing * float(k.frame.sampling.z);
  float low = -ADAPTIVE_LOG2_LAMBDA_RANGE, high = ADAPTIVE_LOG2_LAMBDA_RANGE;
  for (int step = 0; step < ADAPTIVE_BISECTION_STEPS; ++step) {
    const float middle = 0.5f * (low + high);
    (total_at(glm::exp2(middle)) < budget ? low : high) = middle;
  }
  const float lambda = glm::exp2(high);

  // 3. adaptive_shares.comp, over the region's pixels.
  std::vector<std::uint32_t> counts(pixels, 0u);
  for (const PixelRect &rect : shared.rects)
    for (std::uint32_t y = rect.y0; y < rect.y1; ++y)
      for (std::uint32_t x = rect.x0; x < rect.x1; ++x) {
        const std::size_t i = std::size_t(y) * width + x;
        counts[i] =
            k.adaptive_share(weights[i], std::uint32_t(i), lambda, floor_weight, pilot_f, cap);
      }
  return counts;
}

} // namespace camhead::renderer
