// No NaN or infinity reaches an output pixel (issue 4), whatever the scene:
// zero-area and non-finite triangles, spheres of no size, a camera inside an
// object or on a surface, lights inside geometry or on a surface. Scene files
// cannot hold most of these (the loader refuses them, naming the field);
// scenes built in code can, and still render finite.
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/scene_loader.h"
#include "stability_support.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::Light;
using renderer::LightType;
using renderer::MaterialType;
using renderer::Object;
using renderer::RenderResult;
using renderer::Scene;
using renderer::ShapeType;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

void expect_finite(const RenderResult &r, const std::string &what) {
  EXPECT_TRUE(test::all_finite(r.composite)) << what << ": composite";
  EXPECT_TRUE(test::all_finite(r.mixed)) << what << ": mixed";
  EXPECT_TRUE(test::all_finite(r.real)) << what << ": real";
  EXPECT_TRUE(test::all_finite(r.mask)) << what << ": mask";
  EXPECT_TRUE(test::all_finite(r.depth)) << what << ": depth";
}

float max_value(const renderer::Image &image) {
  float m = 0.0f;
  for (float v : image.data) {
    m = std::max(m, v);
  }
  return m;
}

double mean_value(const renderer::Image &image) {
  double sum = 0.0;
  for (float v : image.data) {
    sum += v;
  }
  return sum / double(image.data.size());
}

// A lit scene to put degenerate things into: the shaded stability scene, small.
Scene base_scene() {
  return stability::shaded_scene(48, 36);
}

Light point_light(glm::vec3 position, float power) {
  Light l;
  l.name = "point";
  l.type = LightType::point;
  l.position = position;
  l.power_W = power;
  return l;
}

// ---------------------------------------------------------------- geometry

TEST(Degenerate, ZeroAreaAndNonFiniteTrianglesRenderFinite) {
  auto mesh = std::make_shared<renderer::TriangleMesh>();
  mesh->positions = {{0, 0, 0},    {1, 0, 0},       {2, 0, 0},     // collinear
                     {0, 1, 0},    {0, 1, 0},       {0, 1, 0},     // one point
                     {kNaN, 0, 0}, {kInf, 1, 0},    {0, -kInf, 0}, // not finite
                     {0, 0.3f, 0}, {0.4f, 0.3f, 0}, {0, 0.6f, 0}}; // one proper triangle
  mesh->triangles = {{0, 1, 2}, {3, 4, 5}, {0, 0, 1}, {6, 7, 8}, {0, 6, 1}, {9, 10, 11}};
  Scene scene = base_scene();
  Object m;
  m.name = "degenerate_mesh";
  m.type = ShapeType::mesh;
  m.mesh = mesh;
  m.center = {-0.2f, 0.0f, 1.0f};
  m.scale = 1.0f;
  m.material = 2;
  scene.objects.push_back(m);
  // The thinnest plane and box the loader takes (1e-9 m), and a flat box.
  Object sliver;
  sliver.name = "sliver";
  sliver.type = ShapeType::plane;
  sliver.center = {0.3f, 0.5f, 0.5f};
  sliver.size = {1e-9f, 1.0f, 1.0f};
  sliver.rotation_deg = {90.0f, 0.0f, 0.0f};
  sliver.material = 1;
  scene.objects.push_back(sliver);
  scene.objects.push_back(
      test::box("flat_box", {0.5f, 0.01f, 1.2f}, {0.3f, 1e-9f, 0.3f}, 2, false));
  scene.objects.push_back(test::box("needle", {-0.8f, 0.5f, 0.5f}, {1e-9f, 1.0f, 1e-9f}, 1, true));

  const renderer::CompiledScene compiled = renderer::compile_scene(scene);
  std::size_t triangles = 0;
  for (const auto &p : compiled.primitives) {
    triangles += (glm::floatBitsToUint(p.p0.w) >> 24) == PRIM_TRIANGLE;
  }
  // Kept: ground 2 + crate 12 + virtual box 12 + the one proper mesh
  // triangle + the flat box's top and bottom (4) + the needle's two square
  // ends (4: tiny, but not thin). Dropped: the collinear, one-point and
  // non-finite mesh triangles, the 1e-9 m wide plane and every face 1e-9 m
  // thin (an angle of 3e-9 rad, under the compiler's 1e-6 collinearity bound).
  std::printf("triangles kept: %zu\n", triangles);
  EXPECT_EQ(triangles, 2u + 12u + 12u + 1u + 4u + 4u);
  expect_finite(test::render_cpu(scene, 4), "degenerate triangles");
}

TEST(Degenerate, SpheresOfNoSizeRenderFinite) {
  // radius 0, negative, below float resolution, and not finite: the loader
  // takes none but the tiny one, code can make all of them.
  for (float radius : {0.0f, -0.3f, 1e-30f, 1e-45f, kNaN, kInf}) {
    Scene scene = base_scene();
    scene.objects.push_back(test::sphere("odd", {0.0f, 0.3f, 0.5f}, radius, 3, false));
    const RenderResult r = test::render_cpu(scene, 4);
    expect_finite(r, "sphere radius " + std::to_string(radius));
  }
  // The worst case for a point-sized sphere: a camera ray straight through
  // its centre, where the surface normal is 0/0. One pixel, no jitter.
  for (float radius : {0.0f, 1e-30f}) {
    Scene scene = test::empty_scene("axis", 0.0f, 0.0f, 1, 1);
    scene.render.pixel_filter_width_px = 0.0f;
    scene.materials.push_back({"white", MaterialType::diffuse, glm::vec3(0.8f), 1.5f, {}});
    scene.objects.push_back(test::sphere("point", {0.0f, 0.0f, -2.0f}, radius, 0, false));
    scene.lights.push_back(point_light({0.0f, 1.0f, 0.0f}, 100.0f));
    const RenderResult r = test::render_cpu(scene, 1);
    std::printf("ray through the centre of a sphere of radius %g: mask %g, mixed %g\n",
                double(radius), double(r.mask.data[0]), double(r.mixed.data[0]));
    expect_finite(r, "ray through a point sphere of radius " + std::to_string(radius));
  }
}

TEST(Degenerate, LoaderRefusesShapesOfNoSize) {
  const struct {
    const char *object;
    const char *message;
  } cases[] = {
      {R"({"type": "sphere", "center": [0, 0, -1], "radius": 0, "material": "m"})",
       "tiny.json: objects[0].radius: must be > 0 and <= 1e+06"},
      {R"({"type": "plane", "center": [0, 0, -1], "size": [0, 1], "material": "m"})",
       "tiny.json: objects[0].size: components must be >= 1e-09"},
      {R"({"type": "box", "center": [0, 0, -1], "size": [1, 0, 1], "material": "m"})",
       "tiny.json: objects[0].size: components must be >= 1e-09"},
  };
  for (const auto &c : cases) {
    const std::string json =
        R"({"render": {"width": 8, "height": 6, "samples": 1},
            "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1],
                       "focal_length_mm": 50, "sensor_width_mm": 36},
            "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
            "objects": [)" +
        std::string(c.object) + "]}";
    try {
      (void)renderer::parse_scene(json, "tiny.json");
      ADD_FAILURE() << "accepted " << c.object;
    } catch (const renderer::SceneError &e) {
      std::printf("rejected: %s\n", e.what());
      EXPECT_EQ(std::string(e.what()), c.message);
    }
  }
}

// ---------------------------------------------------------------- camera

TEST(Degenerate, CameraInsideAClosedBoxSeesOnlyWhatIsInside) {
  for (float f_number : {0.0f, 1.4f}) { // pinhole, and lens rays from all over the aperture
    Scene scene = base_scene();
    scene.camera.f_number = f_number;
    scene.camera.focus_distance_m = 0.5f;
    scene.render.world_color = glm::vec3(0.0f);
    // A closed real box around the camera; every light is outside it.
    scene.objects.push_back(test::box("room", scene.camera.position, glm::vec3(1.0f), 1, true));
    const RenderResult dark = test::render_cpu(scene, 4);
    expect_finite(dark, "camera in a box");
    std::printf("f/%.1f, camera inside a closed box, lights outside: max radiance %g\n",
                double(f_number), double(max_value(dark.mixed)));
    EXPECT_EQ(max_value(dark.mixed), 0.0f) << "light leaks into the closed box";
    EXPECT_EQ(max_value(dark.real), 0.0f) << "light leaks into the closed box";
    // ... and a light inside with it.
    scene.lights.push_back(point_light(scene.camera.position + glm::vec3(0.2f, 0.3f, 0.0f), 20.0f));
    const RenderResult lit = test::render_cpu(scene, 4);
    expect_finite(lit, "camera and light in a box");
    EXPECT_GT(mean_value(lit.mixed), 0.01);
  }
}

TEST(Degenerate, CameraInsideGlassMirrorAndOnASurfaceRendersFinite) {
  Scene scene = base_scene();
  scene.render.max_bounces = 16;
  scene.materials.push_back({"glass", MaterialType::glass, glm::vec3(1.0f), 1.5f, {}});
  const int glass = int(scene.materials.size()) - 1;
  // Inside a virtual glass ball.
  Scene in_glass = scene;
  in_glass.objects.push_back(test::sphere("bubble", in_glass.camera.position, 0.5f, glass, false));
  expect_finite(test::render_cpu(in_glass, 4), "camera in glass");
  // Inside a real mirror box with a light: specular paths to the bounce limit.
  Scene in_mirror = scene;
  in_mirror.objects.push_back(test::box("hall", scene.camera.position, glm::vec3(1.0f), 3, true));
  in_mirror.lights.push_back(
      point_light(scene.camera.position + glm::vec3(0.0f, 0.3f, 0.0f), 5.0f));
  const RenderResult mirror = test::render_cpu(in_mirror, 4);
  expect_finite(mirror, "camera in a mirror box");
  // The camera on the ground plane, looking along it; and half its aperture
  // below the ground (f/0.5: a 35 mm radius).
  Scene on_ground = scene;
  on_ground.camera.position = {0.0f, 0.0f, 3.0f};
  on_ground.camera.look_at = {0.0f, 0.0f, 0.0f};
  on_ground.camera.f_number = 0.5f;
  expect_finite(test::render_cpu(on_ground, 4), "camera on the ground");
  // Degenerate camera frames (the loader refuses them): look_at at the
  // camera, up along the view. The frame is empty, not NaN.
  Scene no_view = scene;
  no_view.camera.look_at = no_view.camera.position;
  expect_finite(test::render_cpu(no_view, 1), "look_at == position");
  Scene no_up = scene;
  no_up.camera.up = glm::normalize(no_up.camera.look_at - no_up.camera.position);
  expect_finite(test::render_cpu(no_up, 1), "up along the view");
}

// ---------------------------------------------------------------- lights

TEST(Degenerate, LightInsideAClosedBoxLightsNothingOutside) {
  Scene scene = base_scene();
  scene.lights.clear();
  scene.render.world_color = glm::vec3(0.0f);
  // A closed real box standing on the ground with the only light inside.
  scene.objects.push_back(test::box("lantern", {0.0f, 0.5f, 0.0f}, glm::vec3(0.6f), 1, true));
  scene.lights.push_back(point_light({0.0f, 0.5f, 0.0f}, 500.0f));
  Light panel;
  panel.name = "panel";
  panel.type = LightType::area;
  panel.position = {0.1f, 0.6f, 0.1f};
  panel.size = {0.2f, 0.2f};
  panel.power_W = 200.0f;
  panel.normal = {0.0f, -1.0f, 0.0f};
  scene.lights.push_back(panel);
  const RenderResult r = test::render_cpu(scene, 16);
  expect_finite(r, "light in a box");
  std::printf("light inside a closed box: max radiance outside %g (mixed), %g (real)\n",
              double(max_value(r.mixed)), double(max_value(r.real)));
  EXPECT_EQ(max_value(r.mixed), 0.0f) << "light leaks out of the closed box";
  EXPECT_EQ(max_value(r.real), 0.0f) << "light leaks out of the closed box";
}

TEST(Degenerate, LightsOnSurfacesAndAtTheCameraRenderFinite) {
  const Scene base = base_scene();
  const glm::vec3 ball_center(-0.5f, 0.3f, 0.1f);
  const glm::vec3 crate_corner(0.8f - 0.25f, 0.5f, -0.5f); // on the crate's top face
  for (glm::vec3 position : {glm::vec3(0.3f, 0.0f, 0.5f),  // on the ground plane
                             base.camera.position,         // at the camera
                             ball_center,                  // inside the virtual ball
                             crate_corner}) {
    Scene scene = base;
    scene.lights.push_back(point_light(position, 100.0f));
    expect_finite(test::render_cpu(scene, 4), "point light on a surface");
  }
  // An area light lying in the ground plane, facing up and facing down.
  for (float ny : {1.0f, -1.0f}) {
    Scene scene = base;
    Light panel;
    panel.name = "flush";
    panel.type = LightType::area;
    panel.position = {0.0f, 0.0f, 0.5f};
    panel.size = {1.0f, 1.0f};
    panel.power_W = 100.0f;
    panel.normal = {0.0f, ny, 0.0f};
    scene.lights.push_back(panel);
    expect_finite(test::render_cpu(scene, 4), "area light in the ground plane");
  }
}

TEST(Degenerate, DegenerateScenesRenderFiniteOnGpu) {
  CAMHEAD_REQUIRE_VULKAN();
  Scene scene = base_scene();
  scene.objects.push_back(test::sphere("nothing", {0.0f, 0.3f, 0.5f}, 0.0f, 3, false));
  scene.objects.push_back(
      test::box("flat_box", {0.5f, 0.01f, 1.2f}, {0.3f, 1e-9f, 0.3f}, 2, false));
  scene.objects.push_back(test::box("room", scene.camera.position, glm::vec3(1.0f), 1, true));
  scene.lights.push_back(point_light(scene.camera.position, 20.0f));
  scene.lights.push_back(point_light({0.3f, 0.0f, 0.5f}, 100.0f));
  expect_finite(test::render_gpu(scene, 4), "degenerate scene on the GPU");
}

} // namespace
} // namespace camhead
