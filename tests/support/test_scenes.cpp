#include "test_scenes.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <glm/geometric.hpp>

#include "camhead/renderer/scene_loader.h"
#include "test_support.h"

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

renderer::Light point_light(glm::vec3 position, float power_W) {
  renderer::Light light;
  light.type = renderer::LightType::point;
  light.position = position;
  light.power_W = power_W;
  return light;
}

renderer::Scene edge_scene(float f_number, float focus_m, float depth_m, int width, int height) {
  using namespace renderer;
  Scene scene = empty_scene("edge_scene", f_number, focus_m, width, height);
  scene.materials.push_back({"emitter", MaterialType::emission, glm::vec3(1.0f), 1.5f, {}});
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

renderer::Image noise_plate(int width, int height, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  renderer::Image plate(width, height, 3);
  for (float &v : plate.data)
    v = value(rng);
  return plate;
}

renderer::Scene with_noise_plate(renderer::Scene scene, std::uint32_t seed) {
  scene.plate = noise_plate(scene.render.width, scene.render.height, seed);
  return scene;
}

renderer::Scene random_scene(std::uint32_t seed) {
  std::mt19937 rng(seed);
  const auto uniform = [&](float lo, float hi) {
    return std::uniform_real_distribution<float>(lo, hi)(rng);
  };
  const auto chance = [&](float p) { return uniform(0.0f, 1.0f) < p; };
  const auto pick = [&](int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); };
  const auto point = [&](float r) {
    return glm::vec3(uniform(-r, r), uniform(-r, r), uniform(-r, r));
  };

  renderer::Scene scene = empty_scene("random", 0.0f, 1.0f, 48, 36);
  scene.source = "random scene " + std::to_string(seed);
  scene.render.seed = seed;
  scene.render.max_bounces = pick(4);
  scene.render.pixel_filter_width_px = chance(0.5f) ? 1.0f : uniform(0.5f, 2.5f);
  scene.render.world_color = glm::vec3(uniform(0.0f, 0.3f));
  using renderer::MaterialType;
  scene.materials = {{"grey", MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}},
                     {"red", MaterialType::diffuse, glm::vec3(0.8f, 0.1f, 0.1f), 1.5f, {}},
                     {"mirror", MaterialType::mirror, glm::vec3(0.9f), 1.5f, {}},
                     {"glass", MaterialType::glass, glm::vec3(1.0f), 1.5f, {}},
                     {"lamp", MaterialType::emission, glm::vec3(2.0f), 1.5f, {}}};
  const auto material = [&] {
    const float u = uniform(0.0f, 1.0f);
    return u < 0.55f ? pick(2) : u < 0.75f ? 2 : u < 0.92f ? 3 : 4;
  };
  const auto object = [&](bool real, int index) {
    const std::string name = (real ? "real " : "virtual ") + std::to_string(index);
    const glm::vec3 centre = point(2.0f) + glm::vec3(0.0f, 2.0f, 0.0f);
    renderer::Object o =
        chance(0.5f)
            ? sphere("", centre, uniform(0.05f, 0.8f), material(), real)
            : box("", centre,
                  glm::vec3(uniform(0.05f, 1.5f), uniform(0.05f, 1.5f), uniform(0.05f, 1.5f)),
                  material(), real, point(90.0f));
    o.name = name;
    return o;
  };
  if (chance(0.8f))
    scene.objects.push_back(
        plane("ground", glm::vec3(0.0f), uniform(4.0f, 30.0f), chance(0.85f) ? pick(2) : 2, true));
  for (int i = 0, n = pick(4); i < n; ++i)
    scene.objects.push_back(object(true, i));
  for (int i = 0, n = 1 + pick(3); i < n; ++i)
    scene.objects.push_back(object(false, i));

  for (int i = 0, n = 1 + pick(3); i < n; ++i) {
    renderer::Light light;
    light.name = "light " + std::to_string(i);
    light.color = glm::vec3(uniform(0.5f, 1.0f), uniform(0.5f, 1.0f), uniform(0.5f, 1.0f));
    switch (pick(3)) {
    case 0:
      light.type = renderer::LightType::point;
      light.position = point(4.0f) + glm::vec3(0.0f, 4.0f, 0.0f);
      light.power_W = uniform(20.0f, 500.0f);
      break;
    case 1:
      light.type = renderer::LightType::area;
      light.position = point(4.0f) + glm::vec3(0.0f, 4.0f, 0.0f);
      light.normal = glm::normalize(point(1.0f) - light.position);
      light.size = glm::vec2(uniform(0.1f, 3.0f), uniform(0.1f, 3.0f));
      light.power_W = uniform(20.0f, 500.0f);
      break;
    default:
      light.type = renderer::LightType::sun;
      light.direction = glm::normalize(point(1.0f) - glm::vec3(0.0f, 1.5f, 0.0f));
      light.irradiance_W_m2 = uniform(0.5f, 5.0f);
      break;
    }
    scene.lights.push_back(light);
  }

  renderer::CameraDesc &camera = scene.camera;
  camera.position = point(6.0f) + glm::vec3(0.0f, 3.0f, 0.0f);
  if (chance(0.1f)) // up close to, or inside, something
    camera.position = scene.objects.back().center + point(0.3f);
  camera.look_at = glm::vec3(0.0f, 1.0f, 0.0f) + point(1.5f);
  camera.up = glm::vec3(0.0f, 1.0f, 0.0f);
  if (std::abs(glm::normalize(camera.look_at - camera.position).y) > 0.98f)
    camera.up = glm::vec3(1.0f, 0.0f, 0.0f);
  camera.focal_length_mm = uniform(12.0f, 135.0f);
  camera.f_number = chance(0.25f) ? 0.0f : uniform(1.0f, 16.0f);
  camera.focus_distance_m = uniform(0.3f, 20.0f);
  return with_noise_plate(std::move(scene), seed);
}

renderer::Scene glass_ball_before_lamp(float f_number, float focus_m) {
  renderer::Scene scene = empty_scene("glass ball", f_number, focus_m, 32, 32);
  scene.render.max_bounces = 4;
  scene.materials = {{"glass", renderer::MaterialType::glass, glm::vec3(1.0f), 1.5f, {}},
                     {"lamp", renderer::MaterialType::emission, glm::vec3(1.0f), 1.5f, {}}};
  scene.objects = {
      sphere("ball", glm::vec3(0.0f, 0.0f, -4.0f), 0.3f, 0, false),
      box("lamp", glm::vec3(0.0f, 0.0f, -8.0f), glm::vec3(100.0f, 100.0f, 0.1f), 1, true)};
  return with_noise_plate(std::move(scene), 9);
}

std::vector<renderer::Scene> small_reference_scenes() {
  std::vector<renderer::Scene> scenes;
  for (const char *name : {"ar_basic.json", "boxes.json"})
    scenes.push_back(downscaled(renderer::load_scene(reference_dir() / name), 4));
  for (const char *name : {"scenes/ar_demo.json", "scenes/sim_rig.json"})
    scenes.push_back(downscaled(renderer::load_scene(source_dir() / name), 4));
  for (renderer::Scene &s : scenes)
    if (!s.plate)
      s = with_noise_plate(std::move(s), 7);
  return scenes;
}

} // namespace camhead::test
