#include "test_scenes.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace camhead::test {

renderer::Scene empty_scene(const char *name, float f_number, float focus_m, int width,
                            int height) {
  renderer::Scene scene;
  scene.source = name;
  scene.render.width = width;
  scene.render.height = height;
  scene.camera.position = {0.0f, 0.0f, 0.0f};
  scene.camera.look_at = {0.0f, 0.0f, -1.0f};
  scene.camera.focal_length_mm = 50.0f;
  scene.camera.sensor_width_mm = 36.0f;
  scene.camera.f_number = f_number;
  scene.camera.focus_distance_m = focus_m;
  return scene;
}

namespace {

// What every shape shares; the factories below add their own dimensions.
renderer::Object object(const char *name, renderer::ShapeType type, glm::vec3 center, int material,
                        bool real) {
  renderer::Object o;
  o.name = name;
  o.type = type;
  o.center = center;
  o.material = material;
  o.real = real;
  return o;
}

} // namespace

renderer::Object sphere(const char *name, glm::vec3 center, float radius, int material, bool real) {
  renderer::Object o = object(name, renderer::ShapeType::sphere, center, material, real);
  o.radius = radius;
  return o;
}

renderer::Object box(const char *name, glm::vec3 center, glm::vec3 size, int material, bool real,
                     glm::vec3 rotation_deg) {
  renderer::Object o = object(name, renderer::ShapeType::box, center, material, real);
  o.size = size;
  o.rotation_deg = rotation_deg;
  return o;
}

renderer::Object plane(const char *name, glm::vec3 center, float size_m, int material, bool real) {
  renderer::Object o = object(name, renderer::ShapeType::plane, center, material, real);
  o.size = {size_m, 1.0f, size_m};
  return o;
}

renderer::Scene edge_scene(float f_number, float focus_m, float depth_m, int width, int height) {
  using namespace renderer;
  Scene scene = empty_scene("edge_scene", f_number, focus_m, width, height);
  scene.materials.push_back({"emitter", MaterialType::emission, glm::vec3(1.0f), 1.5f});
  // An XZ plane turned to face the camera, reaching from x = 0 far to the
  // right and far up and down, so that only its left edge is in view.
  const float extent = 1000.0f * depth_m;
  Object half_plane = plane("half_plane", {0.5f * extent, 0.0f, -depth_m}, extent, 0, false);
  half_plane.rotation_deg = {90.0f, 0.0f, 0.0f};
  scene.objects.push_back(half_plane);
  return scene;
}

double coc_px(const renderer::Scene &scene, float depth_m) {
  const auto &c = scene.camera;
  const double f_px = double(c.focal_length_mm) * scene.render.width / c.sensor_width_mm;
  const double f_m = c.focal_length_mm * 1e-3;
  return f_px * (f_m / c.f_number) * std::abs(1.0 / c.focus_distance_m - 1.0 / depth_m);
}

glm::vec2 project(const renderer::Scene &scene, glm::vec3 world) {
  const auto &c = scene.camera;
  const glm::vec3 forward = glm::normalize(c.look_at - c.position);
  const glm::vec3 right = glm::normalize(glm::cross(forward, c.up));
  const glm::vec3 up = glm::cross(right, forward);
  const glm::vec3 d = world - c.position;
  const float f_px = c.focal_length_mm * float(scene.render.width) / c.sensor_width_mm;
  const float z = glm::dot(d, forward);
  return {0.5f * float(scene.render.width) + f_px * glm::dot(d, right) / z,
          0.5f * float(scene.render.height) - f_px * glm::dot(d, up) / z};
}

std::vector<double> row_average(const renderer::Image &image, int c) {
  std::vector<double> profile(image.width, 0.0);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      profile[x] += image.at(x, y)[c] / image.height;
    }
  }
  return profile;
}

double measured_blur_diameter(const std::vector<double> &profile) {
  double sum = 0.0;
  double mean = 0.0;
  for (std::size_t i = 0; i + 1 < profile.size(); ++i) {
    const double lsf = profile[i + 1] - profile[i];
    sum += lsf;
    mean += lsf * double(i + 1);
  }
  mean /= sum;
  double variance = 0.0;
  for (std::size_t i = 0; i + 1 < profile.size(); ++i) {
    const double lsf = profile[i + 1] - profile[i];
    variance += lsf * (double(i + 1) - mean) * (double(i + 1) - mean);
  }
  variance = variance / sum - 1.0 / 6.0;
  return 4.0 * std::sqrt(std::max(variance, 0.0));
}

} // namespace camhead::test
