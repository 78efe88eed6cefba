// The influence region (influence_region.h) is exact: tracing only its
// pixels gives the composite of tracing every pixel, bit for bit, with the
// same seeds. Checked on the reference scenes, the demo and a few hundred
// random scenes (virtual and real objects of every material, every kind of
// light, cameras anywhere, pinholes and wide-open lenses). One differing
// pixel is a pixel the bound missed.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/influence_region.h"
#include "camhead/renderer/scene_loader.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::CompiledScene;
using renderer::Image;
using renderer::InfluenceRegion;
using renderer::Scene;

// A plate of noise: every pixel differs from its neighbours and from what
// the proxy renders, so a pixel composited from a wrong I_m - I_r shows.
Image noise_plate(int width, int height, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  Image plate(width, height, 3);
  for (float &v : plate.data)
    v = value(rng);
  return plate;
}

// The first pixel where two composites differ in any bit, or -1.
long first_difference(const Image &a, const Image &b) {
  if (a.data.size() != b.data.size())
    return 0;
  for (std::size_t i = 0; i < a.data.size(); ++i)
    if (std::memcmp(&a.data[i], &b.data[i], sizeof(float)) != 0)
      return long(i / std::size_t(a.channels));
  return -1;
}

struct Comparison {
  long differing_pixel = -1;
  double fraction = 1.0;
};

// The CPU reference with and without the region, one thread each (the
// samples of a pixel do not depend on the thread count, only the time).
Comparison compare_cpu(const Scene &scene, int rpp) {
  const CompiledScene compiled = renderer::compile_scene(scene);
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, rpp);
  const InfluenceRegion region = renderer::influence_region(compiled, frame);
  const renderer::RenderResult full = renderer::render_cpu(compiled, frame, {}, 1);
  const renderer::RenderResult part = renderer::render_cpu(compiled, frame, {}, 1, &region);
  return {first_difference(full.composite, part.composite), region.fraction()};
}

Scene with_noise_plate(Scene scene, std::uint32_t seed) {
  scene.plate = noise_plate(scene.render.width, scene.render.height, seed);
  return scene;
}

std::vector<Scene> reference_scenes() {
  std::vector<Scene> scenes;
  for (const char *name : {"ar_basic.json", "boxes.json"})
    scenes.push_back(test::downscaled(renderer::load_scene(test::reference_dir() / name), 4));
  scenes.push_back(
      test::downscaled(renderer::load_scene(test::source_dir() / "scenes/ar_demo.json"), 4));
  scenes.push_back(
      test::downscaled(renderer::load_scene(test::source_dir() / "scenes/sim_rig.json"), 4));
  for (Scene &s : scenes)
    if (!s.plate)
      s = with_noise_plate(std::move(s), 7);
  return scenes;
}

// A random scene: a ground most of the time, real and virtual spheres and
// boxes of every material, one to three lights of any kind, the camera
// anywhere within 10 m looking roughly at the objects, a pinhole or a lens
// from f/1 to f/16 focused anywhere from 0.3 m to 20 m.
Scene random_scene(std::uint32_t seed) {
  std::mt19937 rng(seed);
  const auto uniform = [&](float lo, float hi) {
    return std::uniform_real_distribution<float>(lo, hi)(rng);
  };
  const auto chance = [&](float p) { return uniform(0.0f, 1.0f) < p; };
  const auto pick = [&](int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); };
  const auto point = [&](float r) {
    return glm::vec3(uniform(-r, r), uniform(-r, r), uniform(-r, r));
  };

  Scene scene = test::empty_scene("random", 0.0f, 1.0f, 48, 36);
  scene.source = "random scene " + std::to_string(seed);
  scene.render.seed = seed;
  scene.render.max_bounces = pick(4);
  scene.render.pixel_filter_width_px = chance(0.5f) ? 1.0f : uniform(0.5f, 2.5f);
  scene.render.world_color = glm::vec3(uniform(0.0f, 0.3f));
  using renderer::MaterialType;
  scene.materials = {{"grey", MaterialType::diffuse, glm::vec3(0.5f), 1.5f},
                     {"red", MaterialType::diffuse, glm::vec3(0.8f, 0.1f, 0.1f), 1.5f},
                     {"mirror", MaterialType::mirror, glm::vec3(0.9f), 1.5f},
                     {"glass", MaterialType::glass, glm::vec3(1.0f), 1.5f},
                     {"lamp", MaterialType::emission, glm::vec3(2.0f), 1.5f}};
  const auto material = [&] {
    const float u = uniform(0.0f, 1.0f);
    return u < 0.55f ? pick(2) : u < 0.75f ? 2 : u < 0.92f ? 3 : 4;
  };
  const auto object = [&](bool real, int index) {
    const std::string name = (real ? "real " : "virtual ") + std::to_string(index);
    const glm::vec3 centre = point(2.0f) + glm::vec3(0.0f, 2.0f, 0.0f);
    renderer::Object o =
        chance(0.5f)
            ? test::sphere("", centre, uniform(0.05f, 0.8f), material(), real)
            : test::box("", centre,
                        glm::vec3(uniform(0.05f, 1.5f), uniform(0.05f, 1.5f), uniform(0.05f, 1.5f)),
                        material(), real, point(90.0f));
    o.name = name;
    return o;
  };
  if (chance(0.8f))
    scene.objects.push_back(test::plane("ground", glm::vec3(0.0f), uniform(4.0f, 30.0f),
                                        chance(0.85f) ? pick(2) : 2, true));
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

TEST(InfluenceRegion, ReferenceScenesCompositeBitForBit) {
  for (const Scene &scene : reference_scenes()) {
    const Comparison c = compare_cpu(scene, 4);
    std::printf("%s %dx%d: %.1f %% of the pixels traced\n", scene.source.filename().c_str(),
                scene.render.width, scene.render.height, 100.0 * c.fraction);
    EXPECT_EQ(c.differing_pixel, -1)
        << scene.source << ": pixel " << c.differing_pixel << " differs, outside the region";
  }
}

TEST(InfluenceRegion, RandomScenesCompositeBitForBit) {
  constexpr int kScenes = 400;
  int partial = 0;
  double fraction = 0.0;
  for (std::uint32_t seed = 1; seed <= kScenes; ++seed) {
    const Scene scene = random_scene(seed);
    const Comparison c = compare_cpu(scene, 2);
    fraction += c.fraction;
    partial += c.fraction < 1.0 ? 1 : 0;
    EXPECT_EQ(c.differing_pixel, -1)
        << scene.source << ": pixel (" << c.differing_pixel % scene.render.width << ", "
        << c.differing_pixel / scene.render.width << ") differs; region " << c.fraction;
  }
  std::printf("%d random scenes: %.1f %% of the pixels traced on average, %d scenes with a "
              "region smaller than the frame\n",
              kScenes, 100.0 * fraction / kScenes, partial);
  // A region that always took the whole frame would pass the comparison
  // and save nothing.
  EXPECT_GT(partial, kScenes / 2);
}

// The region's reach in the image: the blur circle of a defocused object
// in front of and behind the focal plane, and a wide pixel filter. Many
// small objects, so that some rim lies just past a tile's edge; enough
// samples that the rims' outermost pixels are hit. And a blur circle of
// about 24 px around a ball half as wide, larger than the tiles' slack: a
// blur taken 45 % too small fails here (17 % too small still passes).
TEST(InfluenceRegion, BlurAndFilterReachBitForBit) {
  struct Case {
    const char *name;
    float f_number, focus_m, depth_m, filter_px;
    int balls;
    float radius; // of a ball, over its depth
  };
  for (const Case &c : {Case{"near focus, far objects, f/1.2", 1.2f, 0.6f, 3.0f, 1.0f, 12, 0.004f},
                        Case{"far focus, near objects, f/1.2", 1.2f, 10.0f, 1.0f, 1.0f, 12, 0.004f},
                        Case{"pinhole, 6 px filter", 0.0f, 1.0f, 3.0f, 6.0f, 12, 0.004f},
                        Case{"wide blur, f/0.7", 0.7f, 0.3f, 3.0f, 1.0f, 2, 0.05f}}) {
    Scene scene = test::empty_scene(c.name, c.f_number, c.focus_m, 160, 120);
    scene.render.pixel_filter_width_px = c.filter_px;
    scene.materials = {{"lamp", renderer::MaterialType::emission, glm::vec3(1.0f), 1.5f}};
    for (int i = 0; i < c.balls; ++i) {
      const float x = (float(i % 4) - 1.37f) * 0.23f * c.depth_m;
      const float y = (float(i / 4) - 0.91f) * 0.19f * c.depth_m;
      scene.objects.push_back(
          test::sphere("ball", glm::vec3(x, y, -c.depth_m), c.radius * c.depth_m, 0, false));
    }
    scene = with_noise_plate(std::move(scene), 5);
    const Comparison result = compare_cpu(scene, 16);
    std::printf("%s: %.1f %% traced\n", c.name, 100.0 * result.fraction);
    EXPECT_LT(result.fraction, 1.0) << c.name;
    EXPECT_EQ(result.differing_pixel, -1) << c.name << ": pixel (" << result.differing_pixel % 160
                                          << ", " << result.differing_pixel / 160 << ") differs";
  }
}

// A sphere counts by its own round shape and its shadow by the planes
// tangent to its shadow cone or cylinder, tighter than its box: many
// spheres over a real floor, unlit, lit low by a point light or by a sun, seen
// through a pinhole, so that some rim or shadow edge lies just past a
// tile's edge.
TEST(InfluenceRegion, SphereAndShadowBoundsBitForBit) {
  enum Lighting { none, point, sun };
  for (const Lighting kind : {none, point, sun}) {
    const char *name = kind == none ? "no light" : kind == point ? "point light" : "sun";
    Scene scene = test::empty_scene("spheres", 0.0f, 1.0f, 320, 240);
    scene.camera.position = glm::vec3(0.0f, 1.2f, 0.0f);
    scene.camera.look_at = glm::vec3(0.0f, 0.0f, -4.0f);
    scene.materials = {{"grey", renderer::MaterialType::diffuse, glm::vec3(0.6f), 1.5f}};
    scene.objects.push_back(test::plane("floor", glm::vec3(0.0f, 0.0f, -4.0f), 12.0f, 0, true));
    for (int i = 0; i < 15; ++i) {
      const glm::vec3 centre((float(i % 5) - 2.13f) * 0.71f, 0.15f + 0.07f * float(i % 4),
                             -2.4f - 0.63f * float(i / 5));
      scene.objects.push_back(test::sphere("ball", centre, 0.05f + 0.06f * float(i % 3), 0, false));
    }
    renderer::Light light;
    if (kind == none) {
      // The balls' own bounds alone.
    } else if (kind == sun) {
      light.type = renderer::LightType::sun;
      light.direction = glm::normalize(glm::vec3(1.0f, -0.4f, 0.3f)); // long shadows
      light.irradiance_W_m2 = 3.0f;
    } else {
      light.type = renderer::LightType::point;
      light.position = glm::vec3(-2.5f, 0.6f, -3.0f);
      light.power_W = 200.0f;
    }
    if (kind != none)
      scene.lights.push_back(light);
    scene = with_noise_plate(std::move(scene), 13);
    const Comparison c = compare_cpu(scene, 8);
    std::printf("15 balls over a floor, %s: %.1f %% traced\n", name, 100.0 * c.fraction);
    EXPECT_LT(c.fraction, 0.75) << name;
    EXPECT_EQ(c.differing_pixel, -1) << name << ": pixel (" << c.differing_pixel % 320 << ", "
                                     << c.differing_pixel / 320 << ") differs";
  }
}

// What it saves: a small virtual sphere alone over the plate is a small
// region around its blurred image, and more blur is a larger one.
TEST(InfluenceRegion, SmallObjectSmallRegionGrowingWithBlur) {
  const auto fraction = [](float f_number) {
    Scene scene = test::empty_scene("small sphere", f_number, 0.5f, 320, 240);
    scene.materials = {{"grey", renderer::MaterialType::diffuse, glm::vec3(0.5f), 1.5f}};
    scene.objects.push_back(test::sphere("ball", glm::vec3(0.0f, 0.0f, -4.0f), 0.1f, 0, false));
    renderer::Light sun;
    sun.type = renderer::LightType::sun;
    sun.irradiance_W_m2 = 1.0f;
    scene.lights.push_back(sun);
    scene = with_noise_plate(std::move(scene), 3);
    const CompiledScene compiled = renderer::compile_scene(scene);
    return renderer::influence_region(compiled, renderer::make_frame_params(scene, 1)).fraction();
  };
  const double pinhole = fraction(0.0f), wide = fraction(1.4f);
  std::printf("a 0.2 m ball at 4 m, 320x240: %.2f %% traced as a pinhole, %.2f %% at f/1.4 "
              "focused at 0.5 m\n",
              100.0 * pinhole, 100.0 * wide);
  EXPECT_GT(pinhole, 0.0);
  EXPECT_LT(pinhole, 0.02);
  EXPECT_GT(wide, 2.0 * pinhole);
}

// Without a plate the composite is I_m, which every pixel needs.
TEST(InfluenceRegion, NoPlateTracesTheWholeFrame) {
  Scene scene = random_scene(11);
  scene.plate.reset();
  const CompiledScene compiled = renderer::compile_scene(scene);
  EXPECT_TRUE(
      renderer::influence_region(compiled, renderer::make_frame_params(scene, 1)).whole_frame());
}

TEST(InfluenceRegion, GpuCompositeBitForBit) {
  CAMHEAD_REQUIRE_VULKAN();
  renderer::GpuTracer tracer;
  std::vector<Scene> scenes = reference_scenes();
  for (std::uint32_t seed = 1; seed <= 40; ++seed)
    scenes.push_back(random_scene(seed));
  // A virtual glass ball before a real lamp, as light_transport_test's, at
  // many batches of samples.
  Scene glass = test::empty_scene("glass ball", 0.0f, 1.0f, 32, 32);
  glass.render.max_bounces = 4;
  glass.render.samples = 256;
  glass.materials = {{"glass", renderer::MaterialType::glass, glm::vec3(1.0f), 1.5f},
                     {"lamp", renderer::MaterialType::emission, glm::vec3(1.0f), 1.5f}};
  glass.objects = {
      test::sphere("ball", glm::vec3(0.0f, 0.0f, -4.0f), 0.3f, 0, false),
      test::box("lamp", glm::vec3(0.0f, 0.0f, -8.0f), glm::vec3(100.0f, 100.0f, 0.1f), 1, true)};
  scenes.push_back(with_noise_plate(std::move(glass), 9));
  for (const Scene &scene : scenes) {
    const CompiledScene compiled = renderer::compile_scene(scene);
    tracer.load(compiled);
    const renderer::gpu::FrameParams frame =
        renderer::make_frame_params(scene, scene.render.samples == 256 ? 256 : 4);
    const InfluenceRegion region = renderer::influence_region(compiled, frame);
    const renderer::RenderResult full = tracer.render(frame);
    const renderer::RenderResult part = tracer.render(frame, {}, {}, &region);
    const long differing = first_difference(full.composite, part.composite);
    EXPECT_EQ(differing, -1) << scene.source << ": pixel " << differing << " differs; region "
                             << region.fraction();
    EXPECT_EQ(part.camera_rays, region.pixels() * frame.sampling.z);
  }
}

// Adaptive frames share the region's budget among its pixels: outside it
// the composite is the camera image exactly, and both executors give the
// same shares.
TEST(InfluenceRegion, AdaptiveSharesTheRegionsBudget) {
  const Scene scene = reference_scenes().front();
  const CompiledScene compiled = renderer::compile_scene(scene);
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, 16);
  const InfluenceRegion region = renderer::influence_region(compiled, frame);
  ASSERT_FALSE(region.whole_frame());
  const renderer::RenderResult cpu =
      renderer::render_cpu_adaptive(compiled, frame, {}, {}, 0, &region);
  std::vector<bool> inside(std::size_t(scene.render.width) * scene.render.height, false);
  for (const renderer::PixelRect &r : region.rects)
    for (std::uint32_t y = r.y0; y < r.y1; ++y)
      for (std::uint32_t x = r.x0; x < r.x1; ++x)
        inside[std::size_t(y) * scene.render.width + x] = true;
  std::uint64_t given = 0;
  for (std::size_t i = 0; i < inside.size(); ++i) {
    given += cpu.sample_counts[i];
    if (inside[i])
      continue;
    ASSERT_EQ(cpu.sample_counts[i], 0u) << "pixel " << i;
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(cpu.composite.data[i * 3 + c], scene.plate->data[i * 3 + c]) << "pixel " << i;
  }
  // The budget, in expectation, is the region's pixels at 16 each.
  const double budget = double(region.pixels()) * 16.0;
  EXPECT_NEAR(double(given), budget, 3.0 * std::sqrt(double(region.pixels())) + 1.0);
  EXPECT_EQ(cpu.camera_rays, given);

  if (!test::have_vulkan())
    return;
  renderer::GpuTracer tracer;
  tracer.load(compiled);
  const renderer::RenderResult gpu = tracer.render_adaptive(frame, {}, {}, {}, &region);
  std::size_t same = 0;
  for (std::size_t i = 0; i < inside.size(); ++i)
    same += gpu.sample_counts[i] == cpu.sample_counts[i] ? 1u : 0u;
  // As adaptive_test.cpp: a share on the edge of a rounding step may differ.
  EXPECT_GT(double(same), 0.99 * double(inside.size()));
  EXPECT_EQ(gpu.camera_rays, [&] {
    std::uint64_t n = 0;
    for (const std::uint32_t s : gpu.sample_counts)
      n += s;
    return n;
  }());
}

} // namespace
} // namespace camhead
