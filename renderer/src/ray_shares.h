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

#include "camhead/renderer/gpu_layout.h"
#include "defocus_filter.h"
#include "pixel_span.h"
#include "worker_pool.h"

namespace camhead::renderer::cpu {

inline constexpr std::uint32_t kMostRaysAPixel = 16;

// How many more samples a pixel holding `used` may take below `limit`; 0
// past it (moved samples may pass a limit).
[[nodiscard]] constexpr std::uint32_t sample_room(std::uint32_t limit, std::uint32_t used) {
  return limit > used ? limit - used : 0u;
}
// The noise floor, relative to the pixel's luminance and absolute.
inline constexpr float kNoiseFloor = 0.01f;

struct RayShareBuffers {
  std::span<float> sigma, noise;   // the frame's size each, scratch
  std::span<std::uint32_t> shares; // out: each span pixel's rays
};

// Shares rpp rays a pixel (a mean) of `spans` among them by their noise, from
// the accumulators' `aux` (luminance sum and sum of squares in z, w) and
// `counts` (samples so far, moved ones included: at least one, 0 outside
// the spans); returns the rays given. No pixel goes past `most` samples in
// all, nor past `pattern_room` samples of its own pattern (`own`: those it
// traced so far).
[[nodiscard]] std::uint64_t share_rays_by_noise(std::span<const PixelSpan> spans, int width,
                                                int height, std::span<const glm::vec4> aux,
                                                std::span<const std::uint32_t> counts,
                                                std::span<const std::uint32_t> own, double rpp,
                                                std::uint32_t most, std::uint32_t pattern_room,
                                                std::uint32_t frame_index,
                                                const RayShareBuffers &buffers, WorkerPool &pool);

// A history's first frame, nothing moved into it, has traced one ray a pixel
// and has `rest` more a pixel to give, a mean (every frame of a moving
// camera is one; a fraction where the frame budget lies between two whole
// rays a pixel: FrameRequest::extra_rays_per_pixel).
//   - Where the lens blurs a pixel by kSharpBlurPx or more, the
//     reconstruction (defocus_filter.h) averages it with its neighbours, and
//     those pixels take the rays alike (a fraction of a ray, or below a ray
//     a pixel what the sharp ones leave, in whole blocks of pixels as wide
//     as the reconstruction reaches, at random; a pixel at a time without
//     the reconstruction). Given by the spread of their one-ray
//     neighbourhoods (noise, there) they came out noisier.
//   - Where it is sharp, little smooths it, and one ray a pixel aliases an
//     edge. The sharp pixels share their rays by how much the picture varies
//     about them: the spread of the virtual part of the 3x3 neighbourhood's
//     single samples (their composite less the camera's pixel, which the
//     composite only passes through). It is large at an edge or a shadow's
//     rim, small where the virtual objects change nothing.
//   - With a ray a pixel or more to give, the sharp pixels take as many in
//     all as they would alike. With less, they take theirs first, up to a
//     ray each, and the blurred ones share what is left.
// First frames, `camhead bench live --frames 1`, relative error focused at
// 14 m (bench/RESULTS.md): on the moving rig's scene 0.0348 at 1 rpp,
// 0.0244, 0.0198 and 0.0169 at 1.25, 1.5 and 1.75, and 0.0149 at 2 (0.0264
// with every pixel's rays alike, 9 rpp's 0.0170); on the locked-off rig's
// 0.0419, 0.0370, 0.0351, 0.0300 and 0.0265 (alike 0.0312).
// At 0.5 px the moving rig's scene focused far came out as noisy as with
// every pixel alike, at 0.75 px with a fifth of the gain that 1 px gives.
inline constexpr float kSharpBlurPx = 1.0f;

struct FirstFrameShares {
  double rest = 1.0;                 // rays a pixel after the first, a mean (> 0)
  double reconstruct_strength = 1.0; // the reconstruction's (0: none), for its reach
  std::uint32_t most = 0;            // samples a pixel, at most (max_samples)
  std::uint32_t pattern_room = 0;    // samples of a pixel's own pattern, at most
  std::uint32_t rounding_key = 0;    // a new one each frame
};

struct FirstFrameShared {
  std::uint64_t rays = 0;  // the rays given
  std::uint32_t least = 0; // the fewest any pixel took
  bool uneven = false;     // whether the pixels took different shares
};

// The shares of the rays after the first for each pixel of `spans` (the
// frame's first ray traced in each: `counts` and `own` 1), from the
// accumulators' `aux` and `plate`, the camera frame in linear RGB
// (has_plate): `rest` a pixel on average.
[[nodiscard]] FirstFrameShared
share_first_frame_rays(std::span<const PixelSpan> spans, const gpu::FrameParams &frame,
                       std::span<const glm::vec4> aux, std::span<const glm::vec4> plate,
                       bool has_plate, std::span<const std::uint32_t> counts,
                       std::span<const std::uint32_t> own, const FirstFrameShares &settings,
                       const RayShareBuffers &buffers, WorkerPool &pool);

} // namespace camhead::renderer::cpu
