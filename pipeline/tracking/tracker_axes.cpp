#include "tracker_axes.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/mat3x3.hpp>

namespace camhead::pipeline {
namespace {

constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;

// Columns: the world's coordinates of the stage's X, Y and Z axes.
const glm::dmat3 kStageToWorld(glm::dvec3(1.0, 0.0, 0.0), glm::dvec3(0.0, 0.0, -1.0),
                               glm::dvec3(0.0, 1.0, 0.0));

// Right-handed rotations about the stage's axes (glm::dmat3 is column-major).
glm::dmat3 about_z(double degrees) {
  const double c = std::cos(degrees * kRadiansPerDegree), s = std::sin(degrees * kRadiansPerDegree);
  return {c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0};
}
glm::dmat3 about_x(double degrees) {
  const double c = std::cos(degrees * kRadiansPerDegree), s = std::sin(degrees * kRadiansPerDegree);
  return {1.0, 0.0, 0.0, 0.0, c, s, 0.0, -s, c};
}
glm::dmat3 about_y(double degrees) {
  const double c = std::cos(degrees * kRadiansPerDegree), s = std::sin(degrees * kRadiansPerDegree);
  return {c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c};
}

// A camera turned by `stage_rotation` in the stage frame (its columns the
// camera's right, forward and up) as a world pose. A camera's own axes are
// right, up, back in camhead and right, forward, up on the stage: the same
// change of axes as the world's.
CameraPose world_pose(const hal::lens::TrackedPose &p, const glm::dmat3 &stage_rotation) {
  const glm::dmat3 world = kStageToWorld * stage_rotation * glm::transpose(kStageToWorld);
  return {kStageToWorld * glm::dvec3(p.x_m, p.y_m, p.z_m), glm::normalize(glm::quat_cast(world))};
}

} // namespace

CameraPose from_freed(const hal::lens::TrackedPose &p) {
  return world_pose(p, about_z(-p.pan_deg) * about_x(p.tilt_deg) * about_y(p.roll_deg));
}

CameraPose from_opentrackio(const hal::lens::TrackedPose &p) {
  return world_pose(p, about_z(p.pan_deg) * about_x(p.tilt_deg) * about_y(p.roll_deg));
}

hal::lens::TrackedPose to_opentrackio(const CameraPose &pose) {
  const glm::dmat3 world_to_stage = glm::transpose(kStageToWorld);
  const glm::dvec3 t = world_to_stage * pose.position;
  // R = Rz(pan) Rx(tilt) Ry(roll): its forward column is (-sin pan cos tilt,
  // cos pan cos tilt, sin tilt), its bottom row (-cos tilt sin roll, sin tilt,
  // cos tilt cos roll). glm indexes [column][row].
  const glm::dmat3 r = world_to_stage * glm::mat3_cast(pose.orientation) * kStageToWorld;
  hal::lens::TrackedPose out{.x_m = t.x, .y_m = t.y, .z_m = t.z};
  out.tilt_deg = std::asin(std::clamp(r[1][2], -1.0, 1.0)) / kRadiansPerDegree;
  if (std::abs(r[1][2]) < 1.0 - 1e-12) {
    out.pan_deg = std::atan2(-r[1][0], r[1][1]) / kRadiansPerDegree;
    out.roll_deg = std::atan2(-r[0][2], r[2][2]) / kRadiansPerDegree;
  } else {
    // Straight up or down (sin tilt = s = +-1): the up column is (s sin pan,
    // -s cos pan, 0) with the roll taken as 0.
    const double s = r[1][2] > 0.0 ? 1.0 : -1.0;
    out.pan_deg = std::atan2(s * r[2][0], -s * r[2][1]) / kRadiansPerDegree;
  }
  return out;
}

} // namespace camhead::pipeline
