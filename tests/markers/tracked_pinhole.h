// What the marker pose source's tests share (marker_tracking_test.cpp, the
// sharp board; marker_defocus_test.cpp, the board through defocus): the
// module they open, the 720x576 pinhole they look through, poses aimed at
// a point, and the floor board of synthetic_view.h.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <opencv2/core.hpp>

#include "synthetic_view.h"
#include "tracking/camera_pose.h"
#include "tracking/marker_board.h"
#include "tracking/marker_tracker.h"

namespace camhead::pipeline::test {

// The module the build made, wherever this binary runs from (the loader
// looks beside camhead, not beside the tests).
inline const bool kModuleFound =
    setenv("CAMHEAD_MARKERS_MODULE", CAMHEAD_TEST_MARKERS_MODULE, 0) == 0;

inline constexpr int kWidth = 720, kHeight = 576;

inline CameraModel camera() {
  return pinhole(kWidth, kHeight);
}

inline CameraPose looking_at(glm::dvec3 from, glm::dvec3 at) {
  renderer::FrameCamera c;
  c.position = glm::vec3(from);
  c.look_at = glm::vec3(at);
  CameraPose p = pose_of(c);
  p.position = from; // in double, not through float
  return p;
}

inline double degrees_between(const glm::dquat &a, const glm::dquat &b) {
  return 2.0 * std::acos(std::min(1.0, std::abs(glm::dot(a, b)))) * 180.0 / std::numbers::pi;
}

inline LumaImage luma(const cv::Mat &m) {
  return {m.data, m.cols, m.rows, std::ptrdiff_t(m.step)};
}

inline const MarkerBoard kCharuco = floor_board();
inline const glm::dvec3 kBoardCentre = kFloorBoardCentre;

// The camera 2 m from the board's centre towards `direction`, looking at
// the centre.
inline CameraPose seeing_the_board_from(glm::dvec3 direction) {
  return looking_at(kBoardCentre + 2.0 * glm::normalize(direction), kBoardCentre);
}

} // namespace camhead::pipeline::test
