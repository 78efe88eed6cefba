// The view test of frame_camera.h, apart from compiled_scene.cpp so that the
// scene and board readers (and their fuzz targets) need nothing more.
#include "camhead/renderer/frame_camera.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace camhead::renderer {
namespace {

bool finite(glm::vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// A unit vector, as glm::normalize() gives one when it can: not when the
// squared length underflows (NaN) or overflows (a zero vector) in float.
bool unit(glm::vec3 v) {
  return finite(v) && glm::length(v) > 0.5f;
}

} // namespace

ViewProblem view_problem(glm::vec3 position, glm::vec3 look_at, glm::vec3 up) {
  // The camera's axes as make_frame_params() makes them.
  const glm::vec3 forward = glm::normalize(look_at - position);
  if (!unit(forward))
    return ViewProblem::no_direction;
  if (!unit(glm::normalize(glm::cross(forward, up))))
    return ViewProblem::no_orientation;
  // The scene format's rule (its reference reader tests the unit vectors'
  // cross product against 1e-6), here in double.
  const glm::dvec3 d(look_at - position), u(up);
  if (glm::length(glm::cross(d / glm::length(d), u / glm::length(u))) < 1e-6)
    return ViewProblem::no_orientation;
  return ViewProblem::none;
}

} // namespace camhead::renderer
