#include "defocus_filter.h"

#include <cmath>
#include <cstddef>
#include <initializer_list>

#include <glm/common.hpp>
#include <glm/exponential.hpp>

namespace camhead::renderer::cpu {
namespace rules {
namespace {
// GLSL's types and built-ins, unqualified and named one by one, so that no
// function of these namespaces can hide them.
using glm::ceil;
using glm::max;
using glm::min;
using glm::sqrt;
using glm::vec4;
using std::abs; // fabs, as GLSL's; found before glm's x >= 0 ? x : -x
#define CUBE_ROOT(x) std::cbrt(x)
#include "reconstruct_rules.glsl"
#undef CUBE_ROOT
} // namespace
} // namespace rules

void filter_defocus(const gpu::FrameParams &frame, std::span<const PixelSpan> spans,
                    std::span<const glm::vec4> mixed, std::span<const glm::vec4> real,
                    std::span<const glm::vec4> aux, std::span<const std::uint32_t> counts,
                    const DefocusFilterSettings &settings, const DefocusFilterBuffers &buffers,
                    WorkerPool &pool) {
  const int width = int(frame.image.x);
  const int height = int(frame.image.y);
  const float lens = frame.lens.x * frame.lens.z; // A f: blur radius per dioptre, pixels
  const float inverse_focus = 1.0f / frame.lens.y;
  const float strength = float(settings.strength);
  const float max_reach = float(settings.max_radius_px);
  const auto at = [width](std::uint32_t y, int x) { return std::size_t(y) * width + x; };

  // Each pixel's signed blur radius at its mean depth (a miss: at infinity).
  auto blur_of = [&](int k) {
    const PixelSpan &s = spans[std::size_t(k)];
    for (std::uint32_t x = s.x0; x < s.x1; ++x) {
      const std::size_t i = at(s.y, int(x));
      buffers.blur[i] = rules::reconstruct_blur(aux[i], lens, inverse_focus);
    }
  };
  pool.run(int(spans.size()), blur_of);

  // A sigma of NaN, which no comparison passes, leaves the pixel its own
  // samples.
  const auto sigma_of = [&](std::size_t i) {
    return rules::reconstruct_sigma_of(buffers.blur[i], float(counts[i]), strength, max_reach);
  };
  // Neighbours whose blur circles are alike, which keeps a sharp surface's
  // samples from a far more blurred one's and lets a blurred silhouette's
  // pixels share theirs with the background they spill over. A tighter rule
  // (within half the pixel's own radius) left a 1-rpp frame of the rig
  // focused far twice as noisy (bench/RESULTS.md).
  const auto alike = [&](std::size_t i, std::size_t j) {
    return rules::reconstruct_blurs_alike(buffers.blur[i], buffers.blur[j]);
  };

  // Adds the neighbours at +-1 .. +-reach steps of `step` (whose offsets
  // `valid` allows) with Gaussian weights, three exponentials a pixel for
  // all of them: exp(f (k+1)^2) = exp(f k^2) exp(f (2k + 1)).
  const auto gather = [&](std::size_t i, float sigma, int reach, std::ptrdiff_t step,
                          const auto &valid, const glm::vec4 *m_in, const glm::vec4 *r_in,
                          const auto &n_in, glm::vec4 &m, glm::vec4 &r, float &n) {
    const float falloff = -0.5f / (sigma * sigma);
    float w = std::exp(falloff);
    float ratio = std::exp(3.0f * falloff);
    const float ratio_step = std::exp(2.0f * falloff);
    for (int k = 1; k <= reach; ++k) {
      for (const int side : {-k, k}) {
        if (!valid(side))
          continue;
        const std::size_t j = std::size_t(std::ptrdiff_t(i) + side * step);
        if (counts[j] == 0 || !alike(i, j))
          continue;
        m += w * m_in[j];
        r += w * r_in[j];
        n += w * n_in(j);
      }
      w *= ratio;
      ratio *= ratio_step;
    }
  };
  const auto reach_of = [&](float sigma) { return rules::reconstruct_reach_of(sigma, max_reach); };

  // Rows: weighted sums of the sums, and of the counts.
  auto rows = [&](int k) {
    const PixelSpan &s = spans[std::size_t(k)];
    for (std::uint32_t x = s.x0; x < s.x1; ++x) {
      const std::size_t i = at(s.y, int(x));
      const float sigma = sigma_of(i);
      glm::vec4 m = mixed[i], r = real[i];
      float n = float(counts[i]);
      if (sigma >= settings.min_sigma_px)
        gather(
            i, sigma, reach_of(sigma), 1,
            [&](int dx) { return int(x) + dx >= 0 && int(x) + dx < width; }, mixed.data(),
            real.data(), [&](std::size_t j) { return float(counts[j]); }, m, r, n);
      buffers.scratch_mixed[i] = m;
      buffers.scratch_real[i] = r;
      buffers.scratch_weight[i] = n;
    }
  };
  pool.run(int(spans.size()), rows);

  // Columns of the rows' sums, then the means.
  auto columns = [&](int k) {
    const PixelSpan &s = spans[std::size_t(k)];
    for (std::uint32_t x = s.x0; x < s.x1; ++x) {
      const std::size_t i = at(s.y, int(x));
      const float sigma = sigma_of(i);
      glm::vec4 m = buffers.scratch_mixed[i], r = buffers.scratch_real[i];
      float n = buffers.scratch_weight[i];
      if (sigma >= settings.min_sigma_px)
        gather(
            i, sigma, reach_of(sigma), width,
            [&](int dy) { return int(s.y) + dy >= 0 && int(s.y) + dy < height; },
            buffers.scratch_mixed.data(), buffers.scratch_real.data(),
            [&](std::size_t j) { return buffers.scratch_weight[j]; }, m, r, n);
      buffers.out_mixed[i] = m / n;
      buffers.out_real[i] = r / n;
    }
  };
  pool.run(int(spans.size()), columns);
}

} // namespace camhead::renderer::cpu
