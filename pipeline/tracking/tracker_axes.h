// The network trackers' axes and angles (hal::lens::TrackedPose) in
// camhead's world, and back: the one place that knows which way each
// protocol turns.
//
// Both protocols measure in a stage frame with X right, Y forward (where the
// camera looks at pan, tilt and roll 0) and Z up; camhead's world has y up
// and a camera at rest looking along -z, so a stage point (X, Y, Z) is the
// world point (X, Z, -Y). Both turn pan about the vertical, then tilt about
// the camera's horizontal axis, then roll about its view axis (intrinsic);
// tilt is positive upwards and roll positive clockwise as seen from behind
// the camera in both. They differ in pan:
//   FreeD D1 (Vinten's definition): positive clockwise seen from above, to
//     the right; X, Y horizontal, Z the height, positive up.
//   OpenTrackIO (camdkit's description): right-handed rotations about Z, so
//     a positive pan turns to the left.
// A tracker set up with other axes is corrected at the tracker (every one
// lets its origin and axes be set); the board has no axis mapping.
#pragma once

#include "camera_pose.h"
#include "camhead/hal/lens/lens_encoder.h"

namespace camhead::pipeline {

[[nodiscard]] CameraPose from_freed(const hal::lens::TrackedPose &pose);
[[nodiscard]] CameraPose from_opentrackio(const hal::lens::TrackedPose &pose);
// Angles within (-180, 180], tilt within [-90, 90]; looking straight up or
// down the pan and roll are not separable and pan takes the turn.
[[nodiscard]] hal::lens::TrackedPose to_opentrackio(const CameraPose &pose);

} // namespace camhead::pipeline
