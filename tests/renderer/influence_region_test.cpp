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
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/influence_region.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::CompiledScene;
using renderer::Image;
using renderer::InfluenceRegion;
using renderer::Scene;

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
Comparison compare_cpu(const Scene &scene, int rpp, const renderer::LensModel &lens = {}) {
  const CompiledScene compiled = renderer::compile_scene(scene);
  renderer::FrameCamera camera = renderer::scene_camera(scene);
  camera.lens_model = lens;
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, camera, rpp);
  const InfluenceRegion region = renderer::influence_region(compiled, frame);
  const renderer::RenderResult full = renderer::render_cpu(compiled, frame, {}, 1);
  const renderer::RenderResult part = renderer::render_cpu(compiled, frame, {}, 1, &region);
  return {first_difference(full.composite, part.composite), region.fraction()};
}

TEST(InfluenceRegion, ReferenceScenesCompositeBitForBit) {
  for (const Scene &scene : test::small_reference_scenes()) {
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
    const Scene scene = test::random_scene(seed);
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
    scene.materials = {{"lamp", renderer::MaterialType::emission, glm::vec3(1.0f), 1.5f, {}}};
    for (int i = 0; i < c.balls; ++i) {
      const float x = (float(i % 4) - 1.37f) * 0.23f * c.depth_m;
      const float y = (float(i / 4) - 0.91f) * 0.19f * c.depth_m;
      scene.objects.push_back(
          test::sphere("ball", glm::vec3(x, y, -c.depth_m), c.radius * c.depth_m, 0, false));
    }
    scene = test::with_noise_plate(std::move(scene), 5);
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
    scene.materials = {{"grey", renderer::MaterialType::diffuse, glm::vec3(0.6f), 1.5f, {}}};
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
    scene = test::with_noise_plate(std::move(scene), 13);
    const Comparison c = compare_cpu(scene, 8);
    std::printf("15 balls over a floor, %s: %.1f %% traced\n", name, 100.0 * c.fraction);
    EXPECT_LT(c.fraction, 0.75) << name;
    EXPECT_EQ(c.differing_pixel, -1) << name << ": pixel (" << c.differing_pixel % 320 << ", "
                                     << c.differing_pixel / 320 << ") differs";
  }
}

// Through a lens model (renderer/shaders/lens_model.glsl) the region bounds
// the distorted image: strong barrel, pincushion and tangential lenses with
// the principal point off centre, over random scenes and a field of small
// defocused balls reaching into the corners, where the lens moves things
// most (a region projected through the pinhole misses rims there by tens
// of pixels).
TEST(InfluenceRegion, ThroughALensModelBitForBit) {
  std::vector<renderer::LensModel> lenses(3);
  lenses[0].k1 = -0.3f;
  lenses[0].k2 = 0.08f;
  lenses[0].principal_point = {0.53f, 0.46f};
  lenses[1].k1 = 0.25f;
  lenses[1].k3 = 0.05f;
  lenses[1].fy_over_fx = 0.98f;
  lenses[2].k1 = -0.08f;
  lenses[2].p1 = 0.015f;
  lenses[2].p2 = -0.01f;
  lenses[2].principal_point = {0.47f, 0.52f};
  int partial = 0, compared = 0;
  for (std::size_t k = 0; k < lenses.size(); ++k) {
    for (std::uint32_t seed = 1; seed <= 60; ++seed) {
      const Scene scene = test::random_scene(seed);
      const Comparison c = compare_cpu(scene, 2, lenses[k]);
      ++compared;
      partial += c.fraction < 1.0 ? 1 : 0;
      EXPECT_EQ(c.differing_pixel, -1)
          << "lens " << k << ", " << scene.source << ": pixel ("
          << c.differing_pixel % scene.render.width << ", "
          << c.differing_pixel / scene.render.width << ") differs; region " << c.fraction;
    }
    Scene scene = test::empty_scene("corners", 1.4f, 0.8f, 160, 120);
    scene.materials = {{"lamp", renderer::MaterialType::emission, glm::vec3(1.0f), 1.5f, {}}};
    for (int i = 0; i < 20; ++i) {
      const float x = (float(i % 5) - 2.0f) * 0.36f * 2.5f;
      const float y = (float(i / 5) - 1.5f) * 0.3f * 2.5f;
      scene.objects.push_back(test::sphere("ball", glm::vec3(x, y, -2.5f), 0.01f * 2.5f, 0, false));
    }
    scene = test::with_noise_plate(std::move(scene), 7);
    const Comparison c = compare_cpu(scene, 16, lenses[k]);
    std::printf("lens %zu, 20 defocused balls to the corners: %.1f %% traced\n", k,
                100.0 * c.fraction);
    EXPECT_LT(c.fraction, 1.0) << "lens " << k;
    EXPECT_EQ(c.differing_pixel, -1) << "lens " << k << ": pixel (" << c.differing_pixel % 160
                                     << ", " << c.differing_pixel / 160 << ") differs";
  }
  std::printf("%d scenes through lens models, %d with a region smaller than the frame\n", compared,
              partial);
  EXPECT_GT(partial, compared / 2);
}

// What it saves: a small virtual sphere alone over the plate is a small
// region around its blurred image, and more blur is a larger one.
TEST(InfluenceRegion, SmallObjectSmallRegionGrowingWithBlur) {
  const auto fraction = [](float f_number) {
    Scene scene = test::empty_scene("small sphere", f_number, 0.5f, 320, 240);
    scene.materials = {{"grey", renderer::MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}}};
    scene.objects.push_back(test::sphere("ball", glm::vec3(0.0f, 0.0f, -4.0f), 0.1f, 0, false));
    renderer::Light sun;
    sun.type = renderer::LightType::sun;
    sun.irradiance_W_m2 = 1.0f;
    scene.lights.push_back(sun);
    scene = test::with_noise_plate(std::move(scene), 3);
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
  Scene scene = test::random_scene(11);
  scene.plate.reset();
  const CompiledScene compiled = renderer::compile_scene(scene);
  EXPECT_TRUE(
      renderer::influence_region(compiled, renderer::make_frame_params(scene, 1)).whole_frame());
}

TEST(InfluenceRegion, GpuCompositeBitForBit) {
  CAMHEAD_REQUIRE_VULKAN();
  renderer::GpuTracer tracer;
  std::vector<Scene> scenes = test::small_reference_scenes();
  for (std::uint32_t seed = 1; seed <= 40; ++seed)
    scenes.push_back(test::random_scene(seed));
  // The glass ball, as light_transport_test's, at many batches of samples.
  Scene glass = test::glass_ball_before_lamp(0.0f, 1.0f);
  glass.render.samples = 256;
  scenes.push_back(std::move(glass));
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
  const Scene scene = test::small_reference_scenes().front();
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
