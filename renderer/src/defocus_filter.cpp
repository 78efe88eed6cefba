#include "defocus_filter.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

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

namespace {

// What one pass adds to a pixel: the neighbours at +-1 .. +-reach steps of
// `step` elements (at most `before` steps back and `after` on), those with
// samples and with alike blur circles, with Gaussian weights, each lending
// up to the pixel's own count of samples where `lend_up_to_own`. The
// neighbours go in the order -1, +1, -2, +2, ..., as the GPU's pass takes
// them. A function of plain pointers and local sums: as a lambda over
// captured spans, writing its sums through references, it reloaded every
// pointer and stored every sum at each neighbour, and the filter took 1.4
// times as long (bench/RESULTS.md).
template <typename Weight>
void gather(std::size_t i, const DefocusGaussian &g, int before, int after, std::ptrdiff_t step,
            const float *blur, const std::uint32_t *counts, const glm::vec4 *m_in,
            const glm::vec4 *r_in, const Weight *n_in, bool lend_up_to_own, glm::vec4 &m,
            glm::vec4 &r, float &n) {
  float w = g.weight;
  float ratio = g.ratio;
  const float ratio_step = g.ratio_step;
  const int reach = g.reach;
  const float own_blur = blur[i];
  // The most samples a neighbour lends: the pixel's own count
  // (DefocusFilterSettings::lend_up_to_own), or all of them.
  const float lend_most =
      lend_up_to_own ? float(counts[i]) : std::numeric_limits<float>::infinity();
  // In locals, not through the references: the compiler keeps them in
  // registers.
  glm::vec4 sum_m = m, sum_r = r;
  float sum_n = n;
  for (int k = 1; k <= reach; ++k) {
    const std::ptrdiff_t offsets[2] = {-k * step, k * step};
    const bool inside[2] = {k <= before, k <= after};
    for (int side = 0; side < 2; ++side) {
      const std::size_t j = std::size_t(std::ptrdiff_t(i) + offsets[side]);
      if (!inside[side] || counts[j] == 0 || !rules::reconstruct_blurs_alike(own_blur, blur[j]))
        continue;
      const float lent = w * std::min(1.0f, lend_most / float(counts[j]));
      sum_m += glm::vec4(lent) * m_in[j];
      sum_r += glm::vec4(lent) * r_in[j];
      sum_n += lent * float(n_in[j]);
    }
    w *= ratio;
    ratio *= ratio_step;
  }
  m = sum_m;
  r = sum_r;
  n = sum_n;
}

} // namespace

float defocus_blur_px(const gpu::FrameParams &frame, const glm::vec4 &aux) {
  return rules::reconstruct_blur(aux, frame.lens.x * frame.lens.z, 1.0f / frame.lens.y);
}

float defocus_sigma_px(float blur, float samples, const DefocusFilterSettings &settings) {
  return rules::reconstruct_sigma_of(blur, samples, float(settings.strength),
                                     float(settings.max_radius_px));
}

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

  // Its Gaussian, from its sigma; a sigma below the least, or NaN, which no
  // comparison passes, leaves the pixel its own samples.
  const auto gaussian_of = [&](std::size_t i) {
    const float sigma =
        rules::reconstruct_sigma_of(buffers.blur[i], float(counts[i]), strength, max_reach);
    if (!(sigma >= settings.min_sigma_px))
      return DefocusGaussian{};
    const float falloff = -0.5f / (sigma * sigma);
    return DefocusGaussian{std::exp(falloff), std::exp(3.0f * falloff), std::exp(2.0f * falloff),
                           rules::reconstruct_reach_of(sigma, max_reach)};
  };

  // Neighbours whose blur circles are alike (reconstruct_blurs_alike) keep a
  // sharp surface's samples from a far more blurred one's and let a blurred
  // silhouette's pixels share theirs with the background they spill over. A
  // tighter rule (within half the pixel's own radius) left a 1-rpp frame of
  // the rig focused far twice as noisy (bench/RESULTS.md).
  const float *blur = buffers.blur.data();
  const std::uint32_t *count = counts.data();

  // Rows: weighted sums of the sums, and of the counts.
  auto rows = [&](int k) {
    const PixelSpan &s = spans[std::size_t(k)];
    for (std::uint32_t x = s.x0; x < s.x1; ++x) {
      const std::size_t i = at(s.y, int(x));
      const DefocusGaussian g = gaussian_of(i);
      buffers.gaussian[i] = g;
      glm::vec4 m = mixed[i], r = real[i];
      float n = float(count[i]);
      gather(i, g, int(x), width - 1 - int(x), 1, blur, count, mixed.data(), real.data(), count,
             settings.lend_up_to_own, m, r, n);
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
      const DefocusGaussian g = buffers.gaussian[i];
      glm::vec4 m = buffers.scratch_mixed[i], r = buffers.scratch_real[i];
      float n = buffers.scratch_weight[i];
      gather(i, g, int(s.y), height - 1 - int(s.y), width, blur, count,
             buffers.scratch_mixed.data(), buffers.scratch_real.data(),
             buffers.scratch_weight.data(), settings.lend_up_to_own, m, r, n);
      buffers.out_mixed[i] = m / n;
      buffers.out_real[i] = r / n;
    }
  };
  pool.run(int(spans.size()), columns);
}

} // namespace camhead::renderer::cpu
