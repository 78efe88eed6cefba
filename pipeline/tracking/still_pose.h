// Holds a tracked pose still while the camera is: a marker pose measured
// afresh in every frame jitters with the sensor's noise (bench/RESULTS.md:
// 0.1 mm and 0.005 degree at 1 DN, 0.03-0.06 px), more than the renderer's
// history lets a still view move (render.accumulate_tolerance_px, 0.05 px),
// so a locked-off camera would start its history afresh every frame and
// never converge. The filter is the pose twin of the lens encoders'
// (lens_control's EncoderFilter): while each new measurement moves the
// picture by less than `gate_px` from the pose held, the camera is taken to
// be still, and the pose held is the mean of the first `settle`
// measurements since it came to rest, then that pose unchanged (the
// history then grows from there on); a measurement beyond the gate is the
// camera moving, and is taken as it is.
//
// The cost: a camera creeping by less than the gate a frame is followed in
// steps of up to the gate. Thread safety: none.
#pragma once

#include <cstdint>
#include <span>

#include "camera_pose.h"

namespace camhead::pipeline {

struct StillPoseParams {
  double gate_px = 0.25;    // several times the corners' jitter at 1 DN
  std::uint32_t settle = 8; // measurements averaged once still: a third of a second at 25 fps
};

class StillPoseFilter {
public:
  explicit StillPoseFilter(StillPoseParams p = {}) : p_(p) {}

  // The pose to use for a measurement; `focal_px` and the `points` the
  // camera tracks (a board's corners, world metres) turn a change of pose
  // into pixels of the picture.
  [[nodiscard]] CameraPose filter(const CameraPose &measured, double focal_px,
                                  std::span<const glm::dvec3> points);
  // How far the farthest-moving of `points` moves in the picture, pixels,
  // between a pinhole of focal length `focal_px` at `a` and one at `b`: what
  // a viewer sees of the change (a turn and a shift that cancel on the
  // target, as a planar target's weakest direction does, move nothing).
  [[nodiscard]] static double moved_px(const CameraPose &a, const CameraPose &b, double focal_px,
                                       std::span<const glm::dvec3> points);
  void reset() { count_ = 0; }

private:
  StillPoseParams p_;
  CameraPose held_;
  std::uint32_t count_ = 0;
};

} // namespace camhead::pipeline
