// The view test of frame_camera.h, apart from compiled_scene.cpp so that the
// scene and board readers (and their fuzz targets) need nothing more.
#include "camhead/renderer/frame_camera.h"

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace camhead::renderer {

bool view_has_no_orientation(glm::vec3 position, glm::vec3 look_at, glm::vec3 up) {
  // The reference does this test on float32 vectors (Blender's mathutils),
  // so a direction that vanishes in float is parallel to anything.
  const glm::dvec3 forward(look_at - position), u(up);
  const auto normalized = [](glm::dvec3 v) {
    const double length = glm::length(v);
    return length > 0.0 ? v / length : v;
  };
  return glm::length(glm::cross(normalized(forward), normalized(u))) < 1e-6;
}

} // namespace camhead::renderer
