// calibrate_camera() (marker_tracker.h) inside libcamhead_markers.so: the
// board's ChArUco corners in each view, and OpenCV's fit of the camera to
// them.
#pragma once

#include <string>
#include <vector>

#include "../marker_tracker.h"

namespace camhead::pipeline {

// The camera fitted to `views` of `board` into `out`, or false with `error`
// saying why. OpenCV's exceptions pass through.
bool calibrate_views(const MarkerBoard &board, const std::vector<LumaImage> &views,
                     CameraCalibration &out, std::string &error);

} // namespace camhead::pipeline
