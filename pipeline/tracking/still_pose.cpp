#include "still_pose.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>

namespace camhead::pipeline {

double StillPoseFilter::moved_px(const CameraPose &a, const CameraPose &b, double focal_px,
                                 std::span<const glm::dvec3> points) {
  const auto project = [focal_px](const CameraPose &pose, const glm::dvec3 &point) {
    const glm::dvec3 p = glm::inverse(pose.orientation) * (point - pose.position);
    const double depth = std::max(-p.z, 1e-6); // camhead's camera looks along -z
    return glm::dvec2(p.x, p.y) * (focal_px / depth);
  };
  double moved = 0.0;
  for (const glm::dvec3 &point : points)
    moved = std::max(moved, glm::length(project(a, point) - project(b, point)));
  return moved;
}

CameraPose StillPoseFilter::filter(const CameraPose &measured, double focal_px,
                                   std::span<const glm::dvec3> points) {
  if (count_ == 0 || moved_px(measured, held_, focal_px, points) > p_.gate_px) {
    held_ = measured;
    count_ = 1;
    return held_;
  }
  // The mean of the first `settle` measurements since the camera came to
  // rest (the measurements are a hair apart: the orientation's mean along
  // the arc by the same weight is the mean to far better than their
  // spread), then that pose, unchanged: any change at all, however small,
  // is a new camera to the renderer's history, which bounds it at the
  // scene's nearest depth (a floor under the camera: 5 cm).
  if (count_ >= p_.settle)
    return held_;
  ++count_;
  const double weight = 1.0 / double(count_);
  held_.position += weight * (measured.position - held_.position);
  const glm::dquat to = glm::dot(held_.orientation, measured.orientation) < 0.0
                            ? -measured.orientation
                            : measured.orientation;
  held_.orientation = glm::normalize(glm::slerp(held_.orientation, to, weight));
  return held_;
}

} // namespace camhead::pipeline
