// Accumulating frames (accumulation.h, share_by_noise): each pixel's share of
// a frame's rays where the image still lacks them. Each frame moves every
// pixel toward holding a share of all the rays so far proportional to its
// noise: the standard deviation of its samples' composite luminance, the
// largest in its 3x3 neighbourhood (so that an edge a few samples missed
// still gets rays), plus a floor; for noise sigma_i that minimises the sum
// of sigma_i^2 / n_i for the rays given. Shares are rounded at random (a
// hash of the pixel and the frame), so that they add up to the budget on
// average, and no pixel takes more than kMostRaysAPixel times the frame's
// rays per pixel on one estimate.
#pragma once

#include <cstdint>
#include <span>

#include <glm/vec4.hpp>

#include "pixel_span.h"
#include "worker_pool.h"

namespace camhead::renderer::cpu {

inline constexpr std::uint32_t kMostRaysAPixel = 16;
// The noise floor, relative to the pixel's luminance and absolute.
inline constexpr float kNoiseFloor = 0.01f;

struct RayShareBuffers {
  std::span<float> sigma, noise;   // the frame's size each, scratch
  std::span<std::uint32_t> shares; // out: each span pixel's rays
};

// Shares rpp rays for each pixel of `spans` among them by their noise, from
// the accumulators' `aux` (luminance sum and sum of squares in z, w) and
// `counts` (samples so far, moved ones included: at least one, 0 outside
// the spans); returns the rays given. No pixel goes past `most` samples in
// all, nor past `pattern_room` samples of its own pattern (`own`: those it
// traced so far).
[[nodiscard]] std::uint64_t
share_rays_by_noise(std::span<const PixelSpan> spans, int width, int height,
                    std::span<const glm::vec4> aux, std::span<const std::uint32_t> counts,
                    std::span<const std::uint32_t> own, std::uint32_t rpp, std::uint32_t most,
                    std::uint32_t pattern_room, std::uint32_t frame_index,
                    const RayShareBuffers &buffers, WorkerPool &pool);

} // namespace camhead::renderer::cpu
