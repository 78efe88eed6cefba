// See frame_settings.h; the fields are gpu_layout.h's.
#include "camhead/renderer/frame_settings.h"

#include <glm/geometric.hpp>

namespace camhead::renderer {

void set_camera_sampler(gpu::FrameParams &frame, CameraSampler sampler) {
  frame.tracing.z = sampler == CameraSampler::sobol ? SAMPLER_SOBOL : SAMPLER_CMJ;
}

void set_skip_empty_pixels(gpu::FrameParams &frame, bool on) {
  if (on)
    frame.tracing.w |= TRACING_SKIP_EMPTY_PIXELS;
  else
    frame.tracing.w &= ~TRACING_SKIP_EMPTY_PIXELS;
}

void set_pinhole(gpu::FrameParams &frame) {
  frame.lens.x = 0.0f; // the aperture's radius
}

void set_has_plate(gpu::FrameParams &frame, bool has_plate) {
  frame.image.z = has_plate ? 1u : 0u;
}

std::uint32_t seed(const gpu::FrameParams &frame) {
  return frame.sampling.w;
}

void set_seed(gpu::FrameParams &frame, std::uint32_t seed) {
  frame.sampling.w = seed;
}

std::uint32_t rays_per_pixel(const gpu::FrameParams &frame) {
  return frame.sampling.z;
}

glm::uvec2 image_size(const gpu::FrameParams &frame) {
  return {frame.image.x, frame.image.y};
}

std::optional<glm::vec2> project_to_pixel(const gpu::FrameParams &frame, glm::vec3 world) {
  const glm::vec3 d = world - glm::vec3(frame.cam_position);
  const float z = glm::dot(d, glm::vec3(frame.cam_forward));
  if (!(z > 0.0f))
    return std::nullopt;
  const float focal_px = frame.lens.z;
  return glm::vec2(
      0.5f * float(frame.image.x) + focal_px * glm::dot(d, glm::vec3(frame.cam_right)) / z,
      0.5f * float(frame.image.y) - focal_px * glm::dot(d, glm::vec3(frame.cam_up)) / z);
}

} // namespace camhead::renderer
