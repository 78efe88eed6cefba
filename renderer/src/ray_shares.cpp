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

// A first frame's pixel taking its rays alike (not sharp) is marked so in
// place of a sharp one's want (which is above 0), with the level of the
// block it rounds with (share_first_frame_rays): its side 2^level pixels.
float alike_mark(std::uint32_t level) {
  return -1.0f - float(level);
}
bool is_alike(float want) {
  return want < 0.0f;
}
std::uint32_t alike_level(float mark) {
  return std::uint32_t(-1.0f - mark);
}

// The widest block: the reconstruction's widest reach (2 sigma, at most
// DefocusFilterSettings::max_radius_px), and a bound that the blocks' cell
// numbers rely on.
constexpr std::uint32_t kMostBlockLevel = 4;
static_assert(DefocusFilterSettings{}.max_radius_px <= 1 << kMostBlockLevel);

// The least want of a sharp pixel: its neighbours all alike, a pixel the
// virtual objects may still reach on another ray.
constexpr float kSharpFloor = 0.001f;

// How many more samples a pixel may take: below `most` in all and
// `pattern_room` of its own pattern.
struct SampleLimits {
  std::span<const std::uint32_t> counts, own;
  std::uint32_t most, pattern_room;
};

// Each span pixel's share, wanted(i) rays (a double: 16 times a budget of
// 2^28 rays a pixel would wrap 32 bits) within `limits`, rounded up or down
// at random so that the shares add up to the budget on average; their sum.
// The draw is a hash of `key` and cell(i, x, y): the pixel's own index, or
// one that a block of pixels shares, which then round alike.
template <typename Wanted, typename Cell>
std::uint64_t round_shares(std::span<const PixelSpan> spans, int width, const Wanted &wanted,
                           const Cell &cell, const SampleLimits &limits, std::uint32_t key,
                           std::span<std::uint32_t> shares) {
  CpuKernel hasher; // for sampling.glsl's hash_u32
  std::uint64_t rays = 0;
  for (const PixelSpan &span : spans)
    for (std::uint32_t x = span.x0; x < span.x1; ++x) {
      const std::size_t i = std::size_t(span.y) * std::size_t(width) + x;
      const double want = wanted(i);
      const double whole = std::floor(want);
      const double u =
          double(hasher.hash_u32(cell(i, x, span.y) * 0x9e3779b9u ^ key)) * (1.0 / 4294967296.0);
      const std::uint32_t k = std::uint32_t(whole) + (u < want - whole ? 1u : 0u);
      shares[i] = std::min({k, sample_room(limits.most, limits.counts[i]),
                            sample_room(limits.pattern_room, limits.own[i])});
      rays += shares[i];
    }
  return rays;
}

} // namespace

std::uint64_t share_rays_by_noise(std::span<const PixelSpan> spans, int width, int height,
                                  std::span<const glm::vec4> aux,
                                  std::span<const std::uint32_t> counts,
                                  std::span<const std::uint32_t> own, double rpp,
                                  std::uint32_t most, std::uint32_t pattern_room,
                                  std::uint32_t frame_index, const RayShareBuffers &buffers,
                                  WorkerPool &pool) {
  const auto at = [width](std::uint32_t y, std::uint32_t x) {
    return std::size_t(y) * std::size_t(width) + x;
  };
  std::uint64_t pixels = 0;
  for (const PixelSpan &span : spans)
    pixels += span.x1 - span.x0;
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
  const double most_a_frame = double(kMostRaysAPixel) * double(rpp);
  const auto wanted = [&](std::size_t i) {
    return std::min(double(buffers.noise[i]) * scale, most_a_frame);
  };
  const auto own_cell = [](std::size_t i, std::uint32_t, std::uint32_t) {
    return std::uint32_t(i);
  };
  return round_shares(spans, width, wanted, own_cell, {counts, own, most, pattern_room},
                      frame_index, buffers.shares);
}

FirstFrameShared
share_first_frame_rays(std::span<const PixelSpan> spans, const gpu::FrameParams &frame,
                       std::span<const glm::vec4> aux, std::span<const glm::vec4> plate,
                       bool has_plate, std::span<const std::uint32_t> counts,
                       std::span<const std::uint32_t> own, const FirstFrameShares &settings,
                       const RayShareBuffers &buffers, WorkerPool &pool) {
  const int width = int(frame.image.x);
  const int height = int(frame.image.y);
  const auto at = [width](int y, int x) { return std::size_t(y) * std::size_t(width) + x; };
  // The virtual part of each pixel's sample, in `sigma`: its composite's
  // luminance less the camera's (0 where the virtual objects change nothing).
  const std::span<float> virtual_part = buffers.sigma;
  CpuKernel kernel; // for kernel.glsl's composite_luminance
  auto virtual_part_of = [&](int k) {
    const PixelSpan &span = spans[std::size_t(k)];
    for (std::size_t i = at(int(span.y), int(span.x0)); i < at(int(span.y), int(span.x1)); ++i)
      virtual_part[i] = aux[i].z / float(std::max(counts[i], 1u)) -
                        (has_plate ? kernel.composite_luminance(glm::vec3(plate[i])) : 0.0f);
  };
  pool.run(int(spans.size()), virtual_part_of);
  // A blurred pixel rounds with the aligned block of pixels that its
  // reconstruction reaches over (2 sigma at its one sample, the widest
  // power of two within it on a side, so that the block's pixels' keys are
  // one aligned run of the pattern's Z order, sampling.glsl): the pixels
  // holding a ray more then lie in whole blocks, whose samples spread over
  // the aperture as the pattern's do, and their neighbours' one ray stays
  // the pattern's too. Rounded a pixel at a time, a quarter of a ray a pixel
  // left a blurred frame noisier than one ray alike; a side of 4 or 8 for
  // every blurred pixel made a frame of pixels blurred by one or two 4 %
  // noisier (bench/RESULTS.md).
  const DefocusFilterSettings reconstruction{.strength = settings.reconstruct_strength};
  const auto block_level = [&](float blur) {
    const float reach = 2.0f * defocus_sigma_px(blur, 1.0f, reconstruction);
    std::uint32_t level = 0;
    while (level < kMostBlockLevel && float(2u << level) <= reach)
      ++level;
    return level;
  };
  // A sharp pixel's want, in `noise`: the spread of the virtual part over
  // the traced pixels of its 3x3 neighbourhood, and a floor; alike_mark for the
  // others.
  auto want_of = [&](int k) {
    const PixelSpan &span = spans[std::size_t(k)];
    const int y = int(span.y);
    for (int x = int(span.x0); x < int(span.x1); ++x) {
      const std::size_t i = at(y, x);
      const float blur = defocus_blur_px(frame, aux[i]);
      if (!(std::abs(blur) < kSharpBlurPx)) {
        buffers.noise[i] = alike_mark(block_level(blur));
        continue;
      }
      float sum = 0.0f, squares = 0.0f, n = 0.0f;
      for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, height - 1); ++ny)
        for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, width - 1); ++nx) {
          const std::size_t j = at(ny, nx);
          if (counts[j] == 0) // not traced this frame
            continue;
          sum += virtual_part[j];
          squares += virtual_part[j] * virtual_part[j];
          n += 1.0f;
        }
      const float mean = sum / n; // n >= 1: the pixel itself
      const float spread =
          n > 1.0f ? std::sqrt(std::max(squares - n * mean * mean, 0.0f) / (n - 1.0f)) : 0.0f;
      const float want = spread + kNoiseFloor * std::abs(virtual_part[i]) + kSharpFloor;
      // A sample of inf or NaN must not take every other pixel's rays.
      buffers.noise[i] = std::isfinite(want) ? want : kSharpFloor;
    }
  };
  pool.run(int(spans.size()), want_of);
  // The sharp pixels' rays go where their spread is, the blurred ones' alike.
  // With a ray a pixel after the first or more, the sharp pixels take as
  // many in all as alike; with less, theirs first, up to a ray each (one
  // ray a pixel aliases a sharp edge, and the reconstruction smooths a
  // blurred one), and the blurred ones share what is left, a block of them
  // at a time.
  double want_sum = 0.0, sharp = 0.0, pixels = 0.0;
  for (const PixelSpan &span : spans)
    for (std::size_t i = at(int(span.y), int(span.x0)); i < at(int(span.y), int(span.x1)); ++i) {
      pixels += 1.0;
      if (!is_alike(buffers.noise[i])) {
        want_sum += buffers.noise[i];
        sharp += 1.0;
      }
    }
  const double rest = settings.rest;
  const double sharp_rays = std::min(rest * pixels, sharp * std::max(rest, 1.0));
  const double blurred_each =
      pixels > sharp ? (rest * pixels - sharp_rays) / (pixels - sharp) : 0.0;
  const double scale = want_sum > 0.0 ? sharp_rays / want_sum : 0.0;
  const double most_a_frame = double(kMostRaysAPixel) * (1.0 + rest);
  const auto wanted = [&](std::size_t i) {
    return is_alike(buffers.noise[i]) ? blurred_each
                                      : std::min(double(buffers.noise[i]) * scale, most_a_frame);
  };
  const auto block_cell = [&](std::size_t i, std::uint32_t x, std::uint32_t y) {
    const std::uint32_t level = is_alike(buffers.noise[i]) ? alike_level(buffers.noise[i]) : 0u;
    if (level == 0)
      return std::uint32_t(i);
    // Above the pixels' own indices (a frame has far fewer than 2^31
    // pixels), each level's apart; blocks 2^13 or 2^14 blocks apart share
    // a draw, which ties their rounding but biases nothing.
    return 0x80000000u | (level << 27) | (((y >> level) << 13) & 0x07ffe000u) |
           ((x >> level) & 0x1fffu);
  };
  FirstFrameShared shared;
  shared.rays = round_shares(spans, width, wanted, block_cell,
                             {counts, own, settings.most, settings.pattern_room},
                             settings.rounding_key, buffers.shares);
  std::uint32_t least = ~0u, most = 0;
  for (const PixelSpan &span : spans)
    for (std::size_t i = at(int(span.y), int(span.x0)); i < at(int(span.y), int(span.x1)); ++i) {
      least = std::min(least, buffers.shares[i]);
      most = std::max(most, buffers.shares[i]);
    }
  shared.least = most >= least ? least : 0; // no span: no pixel
  shared.uneven = most > least;
  return shared;
}

} // namespace camhead::renderer::cpu
