// Where the camera is, as the pose sources and the renderer share it: the
// lens's reference point in the scene's world (metres; y up) and the
// camera's orientation, which turns camera axes (x right, y up, looking
// along -z) into world axes, as the scene format's cameras do.
#pragma once

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/frame_camera.h"

namespace camhead::pipeline {

struct CameraPose {
  glm::dvec3 position{0.0};
  glm::dquat orientation{1.0, 0.0, 0.0, 0.0}; // identity: looking along -z, y up

  [[nodiscard]] glm::dvec3 forward() const { return orientation * glm::dvec3(0.0, 0.0, -1.0); }
  [[nodiscard]] glm::dvec3 up() const { return orientation * glm::dvec3(0.0, 1.0, 0.0); }
};

// The pose of a camera given as position, look-at point and up direction
// (a scene file's, a static board's). The view must have a direction and an
// orientation (renderer::view_problem() is none).
[[nodiscard]] CameraPose pose_of(const renderer::FrameCamera &camera);

// `base` (its lens and sensor) placed at `pose`: look_at one metre ahead.
[[nodiscard]] renderer::FrameCamera placed(renderer::FrameCamera base, const CameraPose &pose);

} // namespace camhead::pipeline
