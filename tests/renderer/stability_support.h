// Helpers of the stability suite (issue 4, "Stability where methods fail"):
// flat layered scenes whose images have closed-form thin-lens expectations,
// edge-profile measurements and image statistics.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/image.h"
#include "camhead/renderer/scene.h"
#include "test_scenes.h"

namespace camhead::stability {

constexpr double kPi = 3.14159265358979323846;

// Adds an emission material of grey radiance `radiance`; returns its index.
inline int add_emitter(renderer::Scene &scene, const std::string &name, float radiance) {
  scene.materials.push_back(
      {name, renderer::MaterialType::emission, glm::vec3(radiance), 1.5f, {}});
  return int(scene.materials.size()) - 1;
}

// A plane facing the camera at depth `depth_m` that covers x > x_edge
// (side = +1) or x < x_edge (side = -1), reaching far beyond the view in every
// other direction: one vertical edge. side = 0: the whole view.
inline void add_half_plane(renderer::Scene &scene, const std::string &name, float depth_m,
                           float x_edge, int side, int material, bool real) {
  renderer::Object plane;
  plane.name = name;
  plane.type = renderer::ShapeType::plane;
  const float extent = 1000.0f * depth_m;
  plane.center = {x_edge + 0.5f * extent * float(side), 0.0f, -depth_m};
  plane.size = {extent, 1.0f, extent};
  plane.rotation_deg = {90.0f, 0.0f, 0.0f}; // normal +Y turned to +Z, toward the camera
  plane.material = material;
  plane.real = real;
  scene.objects.push_back(plane);
}

// A small lit AR scene: real ground and box, a virtual diffuse box and a
// virtual mirror ball resting on the ground (contact shadows), a point and an
// area light, a 35 mm f/2.8 lens focused on the middle, and a plate (a smooth
// gradient standing in for the camera image).
inline renderer::Scene shaded_scene(int width, int height) {
  using namespace renderer;
  Scene scene;
  scene.source = "shaded_scene";
  scene.render.width = width;
  scene.render.height = height;
  scene.render.max_bounces = 2;
  scene.render.world_color = glm::vec3(0.05f, 0.06f, 0.08f);
  scene.camera.position = {0.0f, 1.2f, 3.5f};
  scene.camera.look_at = {0.0f, 0.3f, 0.0f};
  scene.camera.focal_length_mm = 35.0f;
  scene.camera.sensor_width_mm = 36.0f;
  scene.camera.f_number = 2.8f;
  scene.camera.focus_distance_m = 3.5f;
  scene.materials.push_back({"ground", MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}});
  scene.materials.push_back(
      {"crate", MaterialType::diffuse, glm::vec3(0.6f, 0.5f, 0.4f), 1.5f, {}});
  scene.materials.push_back(
      {"paint", MaterialType::diffuse, glm::vec3(0.2f, 0.4f, 0.7f), 1.5f, {}});
  scene.materials.push_back({"chrome", MaterialType::mirror, glm::vec3(0.9f), 1.5f, {}});
  scene.objects = {
      test::plane("ground", glm::vec3(0.0f), 20.0f, 0, true),
      test::box("crate", {0.8f, 0.25f, -0.5f}, glm::vec3(0.5f), 1, true, {0.0f, 30.0f, 0.0f}),
      test::box("virtual_box", {0.1f, 0.15f, 0.8f}, glm::vec3(0.3f), 2, false),
      test::sphere("virtual_ball", {-0.5f, 0.3f, 0.1f}, 0.3f, 3, false)};
  Light key;
  key.name = "key";
  key.type = LightType::point;
  key.position = {1.0f, 3.0f, 2.0f};
  key.power_W = 300.0f;
  Light soft;
  soft.name = "soft";
  soft.type = LightType::area;
  soft.position = {-1.0f, 2.5f, 1.0f};
  soft.size = {1.0f, 1.0f};
  soft.power_W = 150.0f;
  soft.normal = glm::normalize(glm::vec3(0.3f, -1.0f, -0.2f));
  scene.lights = {key, soft};
  Image plate(width, height, 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      plate.at(x, y)[0] = 0.1f + 0.3f * float(x) / float(width);
      plate.at(x, y)[1] = 0.15f + 0.2f * float(y) / float(height);
      plate.at(x, y)[2] = 0.2f;
    }
  }
  scene.plate = std::move(plate);
  return scene;
}

// The same scene moved rigidly by `offset` (camera, objects, lights).
inline renderer::Scene translated(renderer::Scene scene, glm::vec3 offset) {
  scene.camera.position += offset;
  scene.camera.look_at += offset;
  for (renderer::Object &o : scene.objects) {
    o.center += offset;
  }
  for (renderer::Light &l : scene.lights) {
    l.position += offset;
  }
  return scene;
}

// Focal length of the projection in pixels.
inline double focal_px(const renderer::Scene &scene) {
  return double(scene.camera.focal_length_mm) * scene.render.width / scene.camera.sensor_width_mm;
}

// Radius in pixels of the disk that the aperture projects to at depth z
// (half the blur-circle diameter): f_px R |1/z - 1/d_f|.
inline double blur_radius_px(const renderer::Scene &scene, double depth_m) {
  const double f_m = scene.camera.focal_length_mm * 1e-3;
  const double aperture_radius = f_m / (2.0 * scene.camera.f_number);
  const double inv_focus =
      std::isinf(scene.camera.focus_distance_m) ? 0.0 : 1.0 / scene.camera.focus_distance_m;
  return focal_px(scene) * aperture_radius * std::abs(1.0 / depth_m - inv_focus);
}

// Fraction of a unit disk with x < s (uniform disk: the chord area).
inline double disk_fraction_below(double s) {
  if (s <= -1.0) {
    return 0.0;
  }
  if (s >= 1.0) {
    return 1.0;
  }
  return (s * std::sqrt(1.0 - s * s) + std::asin(s) + 0.5 * kPi) / kPi;
}

// Thin-lens coverage of an occluding half-plane x < 0 seen from image
// position p (pixels): the fraction of the aperture whose ray through p
// meets the occluder. Its edge projects to column u0 and the aperture
// projects to a uniform disk of radius rho px at its depth, so the covered
// fraction is the part of that disk left of u0 - p.
inline double edge_coverage(double p, double u0, double rho) {
  if (rho <= 0.0) {
    return p < u0 ? 1.0 : 0.0;
  }
  return disk_fraction_below((u0 - p) / rho);
}

// Average of f(p) over pixel column i (box filter of one pixel), by the
// midpoint rule on `steps` points.
template <typename F> double pixel_average(int i, F f, int steps = 256) {
  double sum = 0.0;
  for (int k = 0; k < steps; ++k) {
    sum += f(double(i) + (double(k) + 0.5) / double(steps));
  }
  return sum / double(steps);
}

// Mean absolute difference over all samples of two images of one size.
inline double mean_abs_diff(const renderer::Image &a, const renderer::Image &b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.data.size(); ++i) {
    sum += std::abs(double(a.data[i]) - double(b.data[i]));
  }
  return sum / double(a.data.size());
}

// Number of samples that differ at all.
inline std::size_t differing_samples(const renderer::Image &a, const renderer::Image &b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.data.size(); ++i) {
    n += a.data[i] != b.data[i];
  }
  return n;
}

} // namespace camhead::stability
