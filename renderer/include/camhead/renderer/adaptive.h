// Adaptive ray budget per pixel: rays where the noise is.
//
// A frame of frame.sampling.z samples per pixel on average: a pilot of
// `pilot` samples per pixel, then the rest of the frame budget
// (width x height x sampling.z rays) shared out by allocate_samples() from
// what the pilot saw, and a second pass that traces each pixel's share
// (layout.h, "Adaptive sampling"). Both executors run the same three steps
// (render_cpu_adaptive(), GpuTracer::render_adaptive()); the GPU tracer
// computes the shares on the GPU, between its two passes, with no read-back.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "camhead/renderer/gpu_layout.h"
#include "camhead/renderer/influence_region.h"

namespace camhead::renderer {

struct AdaptiveSampling {
  // Pilot samples per pixel; at most the frame's mean (sampling.z), and at
  // most a quarter of it when that is lower (a pilot must leave rays to share).
  std::uint32_t pilot = 4;
  // No pixel gets more than this many times the frame's mean.
  float max_factor = 16.0f;
  // Weight of the circle of confusion at the pilot's mean depth: a pixel
  // blurred over r pixels counts as if its standard deviation were at least
  // coc_weight x mean luminance x min(r, 8) / 8 (a defocused pixel whose
  // pilot happened to agree is not left at the minimum).
  float coc_weight = 0.05f;
};

// The pilot samples per pixel of a frame of `mean_samples` per pixel.
[[nodiscard]] std::uint32_t adaptive_pilot(const AdaptiveSampling &settings,
                                           std::uint32_t mean_samples);

// FrameParams::adaptive for these settings: the CoC weight and the cap;
// the region's pixel count (z) is the caller's.
[[nodiscard]] gpu::vec4 adaptive_parameters(const AdaptiveSampling &settings, std::uint32_t pilot,
                                            std::uint32_t mean_samples);

// Samples per pixel (pilot included) from the pilot's accumulated aux layer
// (layout.h BINDING_ACCUM_AUX: depth sum, hits, luminance sum, sum of
// squares) of `pilot` samples (renderer/shaders/adaptive.glsl). Every pixel
// gets at least `pilot` and at most the cap; the total is width x height x
// frame.sampling.z in expectation (shares are rounded at random; unless the
// cap forbids it). A pure function of its inputs, and the same steps as the
// GPU tracer's kernels.
//
// With a `region` (influence_region.h) only its pixels take part: the
// budget is its pixels x frame.sampling.z, and the pixels outside get 0
// (their pilot accumulators must be zero, as a pixel not traced has them).
[[nodiscard]] std::vector<std::uint32_t> allocate_samples(std::span<const glm::vec4> pilot_aux,
                                                          const gpu::FrameParams &frame,
                                                          std::uint32_t pilot,
                                                          const AdaptiveSampling &settings,
                                                          const InfluenceRegion *region = nullptr);

} // namespace camhead::renderer
