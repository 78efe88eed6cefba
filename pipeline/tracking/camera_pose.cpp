#include "camera_pose.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace camhead::pipeline {

CameraPose pose_of(const renderer::FrameCamera &camera) {
  const glm::dvec3 position(camera.position);
  const glm::dvec3 back = glm::normalize(position - glm::dvec3(camera.look_at));
  const glm::dvec3 right = glm::normalize(glm::cross(glm::dvec3(camera.up), back));
  const glm::dvec3 up = glm::cross(back, right);
  return {position, glm::quat_cast(glm::dmat3(right, up, back))};
}

renderer::FrameCamera placed(renderer::FrameCamera base, const CameraPose &pose) {
  base.position = glm::vec3(pose.position);
  base.look_at = glm::vec3(pose.position + pose.forward());
  base.up = glm::vec3(pose.up());
  return base;
}

} // namespace camhead::pipeline
