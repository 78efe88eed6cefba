// Reconstruction of a live frame's layers from few samples, with what the
// renderer knows of each pixel: its depth, hence its blur circle. Where the
// lens blurs a surface over c pixels the picture there is smooth at that
// scale, and a pixel's samples may stand in for its neighbours'. So each
// pixel's layers (I_m with the mask, and I_r) become the sample-weighted
// mean of its neighbours' within a Gaussian, among neighbours whose signed
// blur circles are alike (defocus_filter.cpp), in two passes, rows then
// columns.
//
// The Gaussian's sigma is strength sqrt(|c|) / n^(1/3) pixels (n the
// pixel's samples). Widening a blur disk of radius c by a Gaussian of sigma
// widens it by about 2 sigma^2 / c pixels, so this sigma adds the same 2
// strength^2 / n^(2/3) pixels of blur whatever c is: a sigma proportional to
// c (tried first) over-blurred the most defocused parts or left the others
// noisy. It fades as the history grows: as n^(-1/2) it faded too fast for
// samples moved from the frames before (sample_store.h), which are not one
// pattern's; n^(-1/4) too slowly for a held shot's (bench/RESULTS.md).
// Below min_sigma_px a pixel keeps its own samples.
//
// Only traced pixels take part and only the layers are filtered, never the
// camera image: a pixel whose neighbourhood saw nothing virtual (I_m == I_r,
// no mask) keeps I_m == I_r, and its composite stays the camera's.
//
// The GPU executor's twin is renderer/shaders/reconstruct.glsl, the same
// steps in the same order (its exp and cube root the device's), but for
// lend_up_to_own: its pixels all hold the same samples. The rules
// for one pixel (its blur, its sigma and reach, which neighbours are alike)
// are written once, in renderer/shaders/reconstruct_rules.glsl, which both
// compile.
#pragma once

#include <cstdint>
#include <span>

#include <glm/vec4.hpp>

#include "camhead/renderer/gpu_layout.h"
#include "pixel_span.h"
#include "worker_pool.h"

namespace camhead::renderer::cpu {

struct DefocusFilterSettings {
  double strength = 1.0;
  double min_sigma_px = 0.25; // below it a pixel keeps its own samples
  int max_radius_px = 16;     // the widest reach of a pass: 2 sigma, at most
  // A neighbour holding more samples than the pixel lends them with the
  // weight of the pixel's own count: its mean, not its many samples. Where
  // the renderer gave some pixels more rays than others (a first frame's
  // sharp edges, a held shot's noisiest pixels: ray_shares.h), lent whole
  // they stood for their neighbours. First frames of 2 rpp, `camhead bench
  // live` on the locked-off rig's scene, focused at 14 m, at the scene, and
  // the 14-m pull frame afresh: 0.0375, 0.0443 and 0.0370 lent whole;
  // 0.0339, 0.0253 and 0.0351 with the pixels that took more left out (the
  // rule before); 0.0265, 0.0249 and 0.0273 lent up to the pixel's own
  // count. In the columns' pass the rows' sums are lent by the two pixels'
  // own counts, which holds the rule only nearly on the diagonals. Not for
  // a history of samples moved from the frames before
  // (sample_store.h), whose counts differ by where the samples land: there
  // it made the rigs' pull frames up to 6.5 % noisier under three seeds,
  // though the faster pull of tests/renderer/reprojection_test.cpp's ball
  // 25 % less noisy through an ideal lens (2 % through a distorting one;
  // bench/RESULTS.md). The GPU executor's pixels all hold the same samples,
  // and lend whole.
  bool lend_up_to_own = false;
};

// A pixel's Gaussian as both passes walk it, found once in the first: the
// weight of the nearest neighbours, the ratio of the next ones' to theirs,
// that ratio's own ratio (exp(f (k+1)^2) = exp(f k^2) exp(f (2k + 1)):
// three exponentials a pixel for every neighbour), and how many pixels
// either side it reaches (0: the pixel keeps its own samples).
struct DefocusGaussian {
  float weight = 0.0f, ratio = 0.0f, ratio_step = 0.0f;
  int reach = 0;
};

// Sums in, means out: `mixed`, `real` are the accumulators (sums of
// `counts` samples, layout.h), `aux` holds the depth sum and hit count;
// writes each span pixel's filtered means to `out_mixed`, `out_real`, with
// `scratch_*`, `blur` and `gaussian` (the frame's size each) for the
// passes between.
struct DefocusFilterBuffers {
  std::span<glm::vec4> out_mixed, out_real;
  std::span<glm::vec4> scratch_mixed, scratch_real;
  std::span<float> scratch_weight, blur;
  std::span<DefocusGaussian> gaussian;
};

// A pixel's signed blur radius in pixels at the mean depth of its samples,
// from its accumulators `aux` (depth sum and hit count; a miss: at
// infinity): the reconstruction's rule (reconstruct_rules.glsl).
[[nodiscard]] float defocus_blur_px(const gpu::FrameParams &frame, const glm::vec4 &aux);

// A pixel's Gaussian sigma in pixels, from its signed blur radius `blur`
// and its `samples`: the reconstruction's rule (reconstruct_rules.glsl).
[[nodiscard]] float defocus_sigma_px(float blur, float samples,
                                     const DefocusFilterSettings &settings);

void filter_defocus(const gpu::FrameParams &frame, std::span<const PixelSpan> spans,
                    std::span<const glm::vec4> mixed, std::span<const glm::vec4> real,
                    std::span<const glm::vec4> aux, std::span<const std::uint32_t> counts,
                    const DefocusFilterSettings &settings, const DefocusFilterBuffers &buffers,
                    WorkerPool &pool);

} // namespace camhead::renderer::cpu
