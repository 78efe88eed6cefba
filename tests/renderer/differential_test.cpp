// One-pass differential rendering (method.md section 3): the camera image
// passes through untouched where nothing virtual is seen, virtual objects cast
// shadows onto the real proxy, and a virtual mirror shows the real proxy.
#include <cstdio>

#include "camhead/renderer/scene_loader.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::Image;
using renderer::Scene;

Scene without_virtual_objects(Scene scene) {
  std::erase_if(scene.objects, [](const renderer::Object &o) { return !o.real; });
  return scene;
}

// Bit-exact in float: I_f = I_c wherever M = 0 and I_m == I_r.
void expect_plate_passes_through(const Image &composite, const Image &plate) {
  ASSERT_EQ(composite.width, plate.width);
  ASSERT_EQ(composite.height, plate.height);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < plate.data.size(); ++i) {
    differing += composite.data[i] != plate.data[i];
  }
  EXPECT_EQ(differing, 0u) << "of " << plate.data.size() << " samples";
}

TEST(PassThrough, PlateIsUntouchedWithoutVirtualObjectsOnGpu) {
  CAMHEAD_REQUIRE_VULKAN();
  const Scene scene =
      without_virtual_objects(renderer::load_scene(test::reference_dir() / "ar_basic.json"));
  ASSERT_TRUE(scene.plate);
  for (int rpp : {1, 5, 16}) {
    SCOPED_TRACE(testing::Message() << rpp << " rpp");
    const renderer::RenderResult r = test::render_gpu(scene, rpp);
    expect_plate_passes_through(r.composite, *scene.plate);
    EXPECT_EQ(test::rmse(r.mixed, r.real), 0.0);
  }
}

TEST(PassThrough, PlateIsUntouchedWithoutVirtualObjectsOnCpu) {
  const Scene scene = test::downscaled(
      without_virtual_objects(renderer::load_scene(test::reference_dir() / "ar_basic.json")), 4);
  for (int rpp : {1, 3}) {
    SCOPED_TRACE(testing::Message() << rpp << " rpp");
    expect_plate_passes_through(test::render_cpu(scene, rpp).composite, *scene.plate);
  }
}

// A real ground under a point light, a virtual box floating above it, and a
// plate that differs from the real-proxy render (as a camera image would).
Scene shadow_scene() {
  using namespace renderer;
  Scene scene;
  scene.source = "shadow_scene";
  scene.render.width = 160;
  scene.render.height = 120;
  scene.camera.position = {0.0f, 1.0f, 3.0f};
  scene.camera.look_at = {0.0f, 0.3f, 0.0f};
  scene.materials.push_back({"ground", MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}});
  scene.materials.push_back(
      {"paint", MaterialType::diffuse, glm::vec3(0.2f, 0.4f, 0.7f), 1.5f, {}});
  scene.objects = {test::plane("ground", glm::vec3(0.0f), 20.0f, 0, true),
                   test::box("virtual_box", {0.0f, 0.5f, 0.0f}, glm::vec3(0.4f), 1, false)};
  Light key;
  key.name = "key";
  key.type = LightType::point;
  key.position = {0.0f, 4.0f, 0.0f};
  key.power_W = 400.0f;
  scene.lights = {key};
  return scene;
}

TEST(DifferentialRendering, VirtualShadowDarkensThePlateOnRealGeometry) {
  CAMHEAD_REQUIRE_VULKAN();
  Scene scene = shadow_scene();
  // The plate: the real-proxy render brightened by 10 %, as make_plate.py does.
  Image plate = test::render_gpu(without_virtual_objects(scene), 16).real;
  for (float &v : plate.data) {
    v *= 1.1f;
  }
  scene.plate = plate;
  const renderer::RenderResult r = test::render_gpu(scene, 16);
  ASSERT_TRUE(test::all_finite(r.composite));

  // Under the box (umbra of the point light): the ground keeps only the
  // difference between camera image and proxy, I_c - I_r = 0.1 I_r.
  const glm::vec2 umbra = test::project(scene, {0.0f, 0.0f, 0.0f});
  const int ux = int(umbra.x), uy = int(umbra.y);
  EXPECT_EQ(r.mask.at(ux, uy)[0], 0.0f) << "the ground under the box must be visible";
  EXPECT_EQ(r.mixed.at(ux, uy)[0], 0.0f) << "the umbra of a point light receives no light";
  EXPECT_LT(r.composite.at(ux, uy)[0], 0.2f * plate.at(ux, uy)[0]);
  std::printf("umbra pixel (%d, %d): plate %.4f -> composite %.4f\n", ux, uy, plate.at(ux, uy)[0],
              r.composite.at(ux, uy)[0]);

  // Away from box and shadow, the plate passes through bit for bit.
  const glm::vec2 open = test::project(scene, {1.2f, 0.0f, 1.0f});
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(r.composite.at(int(open.x), int(open.y))[c], plate.at(int(open.x), int(open.y))[c]);
  }
  // Where the box is seen, the composite is the mixed render (M = 1).
  const glm::vec2 top = test::project(scene, {0.0f, 0.7f, 0.0f});
  EXPECT_EQ(r.mask.at(int(top.x), int(top.y))[0], 1.0f);
  EXPECT_FLOAT_EQ(r.composite.at(int(top.x), int(top.y))[2], r.mixed.at(int(top.x), int(top.y))[2]);
}

// A virtual mirror panel turned 30 degrees towards a real red box beside the
// camera: the composite shows the box in the mirror. The box is diffuse, so
// (reference README) its reflection needs max_bounces >= 1; with 0 the
// mirror reflects only emitters and the world, which is black here.
TEST(DifferentialRendering, VirtualMirrorReflectsTheRealProxy) {
  CAMHEAD_REQUIRE_VULKAN();
  using namespace renderer;
  Scene scene = shadow_scene();
  scene.camera.position = {0.0f, 0.5f, 2.0f};
  scene.camera.look_at = {0.0f, 0.5f, 0.0f};
  scene.materials.push_back(
      {"red", MaterialType::diffuse, glm::vec3(0.8f, 0.05f, 0.05f), 1.5f, {}});
  scene.materials.push_back({"chrome", MaterialType::mirror, glm::vec3(0.9f), 1.5f, {}});
  Object &box = scene.objects[1]; // now a real red box out of view, right of the camera
  box.material = 2;
  box.real = true;
  box.center = {1.3f, 0.4f, 0.75f};
  box.size = glm::vec3(0.8f);
  Object mirror;
  mirror.name = "virtual_mirror";
  mirror.type = ShapeType::box;
  mirror.center = {0.0f, 0.5f, 0.0f};
  mirror.size = {1.2f, 0.8f, 0.02f};
  mirror.rotation_deg = {0.0f, 30.0f, 0.0f}; // reflects the view towards (0.87, 0, 0.5)
  mirror.material = 3;
  scene.objects.push_back(mirror);
  scene.lights[0].position = {0.5f, 3.0f, 2.0f};

  // Mirror pixels (M = 1) whose colour is clearly the box's red.
  auto red_reflections = [&](int bounces) {
    scene.render.max_bounces = bounces;
    const RenderResult r = test::render_gpu(scene, 16);
    int mirror_pixels = 0, red = 0;
    for (int y = 0; y < r.mask.height; ++y) {
      for (int x = 0; x < r.mask.width; ++x) {
        if (r.mask.at(x, y)[0] != 1.0f) {
          continue;
        }
        ++mirror_pixels;
        const float *c = r.composite.at(x, y);
        // M = 1: the composite is the mixed render (equation 4).
        EXPECT_NEAR(c[0], r.mixed.at(x, y)[0], 1e-5f);
        red += c[0] > 0.01f && c[0] > 4.0f * c[1] && c[0] > 4.0f * c[2];
      }
    }
    EXPECT_GT(mirror_pixels, 500);
    std::printf("max_bounces %d: %d of %d mirror pixels show the red box\n", bounces, red,
                mirror_pixels);
    return red;
  };
  EXPECT_GT(red_reflections(1), 100) << "the real red box must show in the virtual mirror";
  EXPECT_EQ(red_reflections(0), 0) << "a diffuse surface seen in a mirror needs max_bounces >= 1";
}

} // namespace
} // namespace camhead
