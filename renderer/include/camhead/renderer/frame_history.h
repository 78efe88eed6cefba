// Accumulation while nothing changes (issue 24): a camera head often holds a
// shot, and while the pose, the lens and the scene stay put each live frame's
// samples add to those of the frames before, so that the virtual image
// converges to the reference instead of showing one frame's noise.
//
// A history is a render of one camera (the frame that started it): its
// samples are indices [0, n) of one progressive pattern (Owen-scrambled
// Sobol' for the camera ray, the frame's seed), and each frame adds the next
// indices, never the same ones again. N frames of one sample each therefore
// give the same image, bit for bit, as one frame of N samples
// (tests/renderer/frame_history_test.cpp). A frame whose camera differs
// from the history's by more than the tolerance, measured in pixels of blur
// circle or position (frame_change_px), starts a new history: the first frame
// after a focus jump carries nothing of the frames before it. Within the
// tolerance the history's own camera is traced on, so the image shown lags
// the lens by at most that much.
#pragma once

#include <cstdint>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/gpu_layout.h"

namespace camhead::renderer {

struct AccumulationSettings {
  bool enabled = false;
  // The largest movement, in pixels, of any point's blur circle or position
  // that keeps a history: below what a viewer can see (the blur follows a
  // focus pull within 0.1 px), above encoder noise after the lens chain's
  // filter and hold.
  double tolerance_px = 0.05;
  // Samples per pixel at which a history stops growing: from there a still
  // frame traces nothing (the reference at 1024 is only 4x less noisy).
  std::uint32_t max_samples = 256;
  // After a few samples everywhere, give each frame's rays to the pixels
  // whose samples disagree most (the blurred edges and shadows) rather than
  // to every pixel alike. Off, N still frames of k rays are exactly one
  // frame of N k rays (tests/renderer/frame_history_test.cpp); on, each
  // pixel's picture is exactly one of its own count of samples.
  bool share_by_noise = true;
  // Let each pixel borrow its neighbours' samples within a Gaussian of
  // sigma = strength sqrt(blur radius / samples) pixels, among neighbours of
  // alike blur (renderer/src/defocus_filter.h): a 1-rpp frame of a strongly
  // defocused shot is as clean as 9 rpp. Only the traced pixels take part,
  // so with it on the influence region and the whole frame give different
  // (equally valid) estimates; the camera image outside the region stays
  // exact.
  bool reconstruct = true;
  double reconstruct_strength = 1.0;
};

// The nearest depth along the view axis from `frame`'s entrance pupil at
// which `scene` has anything: its bounds' nearest corner, but never nearer
// than kNearestDepthM (a scene whose bounds reach behind the lens, as a floor
// under the camera does).
inline constexpr double kNearestDepthM = 0.05;
[[nodiscard]] double nearest_depth_m(const CompiledScene &scene, const gpu::FrameParams &frame);

// An upper bound, in pixels, on how far any point of the scene at a depth of
// at least `nearest_m` moves between frames `a` and `b`, in position (the
// pupil moving, the image scale breathing) plus in blur-circle radius (focus
// and aperture), to first order in the change. Infinity where the frames
// differ in anything else that shapes the image: the view's direction, the
// image size, the pixel filter, the lights, the world colour or the plate.
[[nodiscard]] double frame_change_px(const gpu::FrameParams &a, const gpu::FrameParams &b,
                                     double nearest_m);

} // namespace camhead::renderer
