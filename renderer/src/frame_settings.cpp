// See frame_settings.h; the fields are gpu_layout.h's.
#include "camhead/renderer/frame_settings.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "lens_model_math.h"

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

bool has_lens_model(const gpu::FrameParams &frame) {
  return (frame.tracing.w & TRACING_LENS_MODEL) != 0u;
}

glm::vec2 ideal_to_pixel(const gpu::FrameParams &frame, glm::vec2 ideal) {
  if (!has_lens_model(frame))
    return 0.5f * glm::vec2(image_size(frame)) + frame.lens.z * ideal;
  const glm::vec2 d =
      cpu::LensModelMath{}.lens_distort(ideal, frame.distortion, frame.projection.w);
  return {frame.projection.x + frame.lens.z * d.x,
          frame.projection.y + frame.lens.z * frame.projection.z * d.y};
}

glm::vec2 pixel_to_ideal(const gpu::FrameParams &frame, glm::vec2 pixel) {
  if (!has_lens_model(frame))
    return (pixel - 0.5f * glm::vec2(image_size(frame))) / frame.lens.z;
  return cpu::LensModelMath{}.lens_undistort(
      {(pixel.x - frame.projection.x) / frame.lens.z,
       (pixel.y - frame.projection.y) / (frame.lens.z * frame.projection.z)},
      frame.distortion, frame.projection.w);
}

LensExtent lens_extent(const gpu::FrameParams &frame, double margin) {
  const double width = frame.image.x, height = frame.image.y;
  if (!has_lens_model(frame))
    return {0.5 * std::hypot(width, height) / double(frame.lens.z), 1.0, 1.0, 0.0};
  LensExtent extent{0.0, 0.0, INFINITY, 0.0};
  glm::dvec2 lo(INFINITY), hi(-INFINITY);
  const auto take = [&](double u, double v) {
    const glm::dvec2 ideal(pixel_to_ideal(frame, glm::vec2(float(u), float(v))));
    extent.max_tan = std::max(extent.max_tan, glm::length(ideal));
    lo = glm::min(lo, ideal);
    hi = glm::max(hi, ideal);
  };
  constexpr double kStepPx = 4.0;
  for (double u = 0.0; u < width + kStepPx; u += kStepPx) {
    take(std::min(u, width), 0.0);
    take(std::min(u, width), height);
  }
  for (double v = 0.0; v < height + kStepPx; v += kStepPx) {
    take(0.0, std::min(v, height));
    take(width, std::min(v, height));
  }
  lo -= margin;
  hi += margin;
  constexpr int kGrid = 16;
  const double fx = frame.lens.z, fy = double(frame.lens.z) * double(frame.projection.z);
  for (int j = 0; j <= kGrid; ++j)
    for (int i = 0; i <= kGrid; ++i) {
      const glm::dvec2 p = lo + (hi - lo) * glm::dvec2(i, j) / double(kGrid);
      const glm::dvec3 jac(
          cpu::LensModelMath{}.lens_jacobian(glm::vec2(p), frame.distortion, frame.projection.w));
      // The image's Jacobian in pixels, its columns d/dx and d/dy, and
      // their spectral norm over the ideal plane's pixels (a focal length
      // of lens.z).
      const glm::dvec2 dx(fx * jac.x, fy * jac.z), dy(fx * jac.z, fy * jac.y);
      const double row = ideal_to_pixel(frame, glm::vec2(p)).y;
      extent.max_row_shift_px = std::max(
          extent.max_row_shift_px, 1.1 * std::abs(row - (double(frame.projection.y) + fy * p.y)));
      const double a = glm::dot(dx, dx), b = glm::dot(dx, dy), c = glm::dot(dy, dy);
      const double spread = std::sqrt(0.25 * (a - c) * (a - c) + b * b);
      extent.stretch =
          std::max(extent.stretch, std::sqrt(0.5 * (a + c) + spread) / double(frame.lens.z));
      extent.least_stretch =
          std::min(extent.least_stretch,
                   std::sqrt(std::max(0.5 * (a + c) - spread, 0.0)) / double(frame.lens.z));
    }
  return extent;
}

std::optional<glm::vec2> project_to_pixel(const gpu::FrameParams &frame, glm::vec3 world) {
  const glm::vec3 d = world - glm::vec3(frame.cam_position);
  const float z = glm::dot(d, glm::vec3(frame.cam_forward));
  if (!(z > 0.0f))
    return std::nullopt;
  if (has_lens_model(frame))
    return ideal_to_pixel(frame, {glm::dot(d, glm::vec3(frame.cam_right)) / z,
                                  -glm::dot(d, glm::vec3(frame.cam_up)) / z});
  const float focal_px = frame.lens.z;
  return glm::vec2(
      0.5f * float(frame.image.x) + focal_px * glm::dot(d, glm::vec3(frame.cam_right)) / z,
      0.5f * float(frame.image.y) - focal_px * glm::dot(d, glm::vec3(frame.cam_up)) / z);
}

} // namespace camhead::renderer
