// Accumulation while nothing changes: a camera head often holds a shot, and
// while the pose, the lens and the scene stay put each live frame's samples
// add to those of the frames before, so that the virtual image converges to
// the reference instead of showing one frame's noise.
//
// A history is a render of one camera (the frame that started it): its
// samples are indices [0, n) of one progressive pattern (Owen-scrambled
// Sobol' for the camera ray, the frame's seed), and each frame adds the next
// indices, never the same ones again. N frames of one sample each therefore
// give the same image, bit for bit, as one frame of N samples
// (tests/renderer/frame_history_test.cpp). A frame whose camera differs
// from the history's by more than the tolerance, measured in pixels of blur
// circle or position (frame_change_px), starts a new history: the first frame
// after a focus jump carries nothing of the frames before it, or, where the
// pose held and the live settings ask (accumulation.h, reproject; the CPU
// reference), their samples moved to the pixels that see their rays through
// the new lens, which carry nothing of the old focus either
// (renderer/src/sample_store.h). Within the tolerance the history's own
// camera is traced on, so the image shown lags the lens by at most that much.
#pragma once

#include "camhead/renderer/accumulation.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/gpu_layout.h"

namespace camhead::renderer {

// The nearest depth along the view axis from `frame`'s entrance pupil at
// which `scene` has anything: its bounds' nearest corner, but never nearer
// than kNearestDepthM (a scene whose bounds reach behind the lens, as a floor
// under the camera does).
inline constexpr double kNearestDepthM = 0.05;
[[nodiscard]] double nearest_depth_m(const CompiledScene &scene, const gpu::FrameParams &frame);

// An upper bound, in pixels, on how far any point of the scene at a depth of
// at least `nearest_m` moves between frames `a` and `b`, in position (the
// pupil moving, the view turning, the image scale breathing) plus in
// blur-circle radius (focus, aperture, the depth along a turned view), to
// first order in the change. Infinity where the frames differ in anything
// else that shapes the image: the image size, the pixel filter, the lights,
// the world colour or the plate.
[[nodiscard]] double frame_change_px(const gpu::FrameParams &a, const gpu::FrameParams &b,
                                     double nearest_m);

} // namespace camhead::renderer
