// Albedo textures (scene.h, Material::albedo_texture): where a texture lands
// on a plane and a box, that both executors read it alike, that a texture
// finer than the pixels is seen as its mean (no aliasing), and that a wrong
// texture is refused with the file and field named.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/image_io.h"
#include "camhead/renderer/scene_loader.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::Image;
using renderer::RenderResult;
using renderer::Scene;

// A page of four coloured quarters: red top left, green top right, blue
// bottom left, white bottom right, `side` pixels square.
Image quarters(int side) {
  Image image(side, side, 3);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const bool right = x >= side / 2, bottom = y >= side / 2;
      const glm::vec3 c = !bottom ? (right ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0))
                                  : (right ? glm::vec3(1) : glm::vec3(0, 0, 1));
      float *px = image.at(x, y);
      px[0] = c.r;
      px[1] = c.g;
      px[2] = c.b;
    }
  return image;
}

// A checkerboard of single black and white pixels.
Image fine_checker(int side) {
  Image image(side, side, 3);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x)
      for (int c = 0; c < 3; ++c)
        image.at(x, y)[c] = float((x + y) % 2);
  return image;
}

// A 64 x 64 pinhole camera at the origin looking down -z (1 m at 2 m spans
// 32 px), a sun shining along -z with irradiance pi, so that a lit surface
// facing the camera has radiance = its albedo, and `object`.
std::string scene_json(const std::string &object, const std::string &material) {
  return R"({
    "render": {"width": 64, "height": 64, "samples": 1, "seed": 1, "max_bounces": 0,
               "world_color": [0, 0, 0]},
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0],
               "focal_length_mm": 36, "sensor_width_mm": 36},
    "materials": {"page": )" +
         material + R"(},
    "objects": [)" +
         object + R"(],
    "lights": [{"type": "sun", "direction": [0, 0, -1], "irradiance_W_m2": 3.14159265,
                "color": [1, 1, 1]}]})";
}

// The 1 m plane at 2 m, upright facing the camera: its own +y turned to +z.
constexpr const char *kFacingPlane =
    R"({"type": "plane", "center": [0, 0, -2], "size": [1, 1], "rotation_deg": [90, 0, 0],
        "material": "page", "real": true})";
// A 1 m box whose front face is at 2 m.
constexpr const char *kBox =
    R"({"type": "box", "center": [0, 0, -2.5], "size": [1, 1, 1], "material": "page",
        "real": true})";
// The same box turned so that each other face looks at the camera: its own
// -x side, its back, its +x side, its top and its bottom. Each is upright
// seen from outside (a side), or as a plane turned up to face the camera
// (the top; the bottom seen from below).
constexpr const char *kTurnedBoxes[] = {
    R"({"type": "box", "center": [0, 0, -2.5], "size": [1, 1, 1], "rotation_deg": [0, 90, 0],
        "material": "page", "real": true})",
    R"({"type": "box", "center": [0, 0, -2.5], "size": [1, 1, 1], "rotation_deg": [0, 180, 0],
        "material": "page", "real": true})",
    R"({"type": "box", "center": [0, 0, -2.5], "size": [1, 1, 1], "rotation_deg": [0, -90, 0],
        "material": "page", "real": true})",
    R"({"type": "box", "center": [0, 0, -2.5], "size": [1, 1, 1], "rotation_deg": [90, 0, 0],
        "material": "page", "real": true})",
    R"({"type": "box", "center": [0, 0, -2.5], "size": [1, 1, 1], "rotation_deg": [-90, 0, 0],
        "material": "page", "real": true})"};

std::vector<RenderResult> render_both(const Scene &scene, int rpp) {
  std::vector<RenderResult> results{test::render_cpu(scene, rpp)};
  if (test::have_vulkan())
    results.push_back(test::render_gpu(scene, rpp));
  return results;
}

glm::vec3 pixel(const Image &image, int x, int y) {
  const float *px = image.at(x, y);
  return {px[0], px[1], px[2]};
}

class Texture : public ::testing::TestWithParam<const char *> {};

// The page's quarters appear where the scene format puts them, upright, in
// their colours (a lit face of albedo a has radiance a here), on both
// executors. The face spans pixels 16 .. 47; each quarter's middle is 8 px
// from its edges.
TEST_P(Texture, LandsUprightWithItsColours) {
  test::ScratchDir dir;
  renderer::write_image(dir.path() / "page.png", quarters(64));
  const Scene scene =
      renderer::parse_scene(scene_json(GetParam(), R"({"type": "diffuse", "albedo_texture":
                                                        "page.png"})"),
                            dir.path() / "scene.json");
  struct Quarter {
    int x, y;
    glm::vec3 colour;
  };
  for (const RenderResult &r : render_both(scene, 4)) {
    for (const Quarter &q : {Quarter{24, 24, {1, 0, 0}}, Quarter{39, 24, {0, 1, 0}},
                             Quarter{24, 39, {0, 0, 1}}, Quarter{39, 39, {1, 1, 1}}}) {
      const glm::vec3 seen = pixel(r.composite, q.x, q.y);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(seen[c], q.colour[c], 2e-3)
            << "pixel " << q.x << "," << q.y << " channel " << c;
    }
    // Beyond the face: the black world.
    EXPECT_EQ(pixel(r.composite, 8, 32), glm::vec3(0.0f));
  }
}

// A texture a tint multiplies: albedo [0.5, 0.25, 1] over white is that.
TEST_P(Texture, IsTintedByTheAlbedo) {
  test::ScratchDir dir;
  renderer::write_image(dir.path() / "page.png", quarters(64));
  const Scene scene = renderer::parse_scene(
      scene_json(GetParam(),
                 R"({"type": "diffuse", "albedo": [0.5, 0.25, 1], "albedo_texture": "page.png"})"),
      dir.path() / "scene.json");
  for (const RenderResult &r : render_both(scene, 4)) {
    const glm::vec3 seen = pixel(r.composite, 39, 39);
    EXPECT_NEAR(seen.r, 0.5f, 1e-3);
    EXPECT_NEAR(seen.g, 0.25f, 1e-3);
    EXPECT_NEAR(seen.b, 1.0f, 2e-3);
  }
}

std::string shape_name(const ::testing::TestParamInfo<const char *> &shape) {
  constexpr const char *kNames[] = {"Plane",        "BoxFront", "BoxLeftSide", "BoxBack",
                                    "BoxRightSide", "BoxTop",   "BoxBottom"};
  return kNames[shape.index];
}

INSTANTIATE_TEST_SUITE_P(Shapes, Texture,
                         ::testing::Values(kFacingPlane, kBox, kTurnedBoxes[0], kTurnedBoxes[1],
                                           kTurnedBoxes[2], kTurnedBoxes[3], kTurnedBoxes[4]),
                         shape_name);

// Materials that name one file share one image, and the compiled scene
// holds its texels once.
TEST(TextureSharing, AFileNamedTwiceIsReadAndStoredOnce) {
  test::ScratchDir dir;
  renderer::write_image(dir.path() / "page.png", quarters(64));
  const std::string json = R"({
    "render": {"width": 8, "height": 8, "samples": 1},
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0],
               "focal_length_mm": 36, "sensor_width_mm": 36},
    "materials": {"one": {"type": "diffuse", "albedo_texture": "page.png"},
                  "other": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5],
                            "albedo_texture": "./page.png"}},
    "objects": [
      {"type": "plane", "center": [0, 0, -2], "size": [1, 1], "material": "one"},
      {"type": "plane", "center": [0, 0, -3], "size": [1, 1], "material": "other"}]})";
  const Scene scene = renderer::parse_scene(json, dir.path() / "scene.json");
  ASSERT_EQ(scene.materials.size(), 2u);
  EXPECT_EQ(scene.materials[0].albedo_texture.image, scene.materials[1].albedo_texture.image);
  const renderer::CompiledScene both = renderer::compile_scene(scene);
  Scene one = scene;
  one.objects.pop_back();
  one.materials.pop_back();
  // Two planes' uv records (2 triangles, 2 texels each) more, the texture not again.
  EXPECT_EQ(both.surfaces.size(), renderer::compile_scene(one).surfaces.size() + 4u);
}

// A checker of 1-texel squares, 8 texels to a pixel, seen with one ray per
// pixel: sampled at points it would be a random black or white pixel each;
// filtered to the pixel it is its mean, 0.5, everywhere on the face.
TEST(TextureFiltering, APatternFinerThanThePixelsIsSeenAsItsMean) {
  test::ScratchDir dir;
  renderer::write_image(dir.path() / "checker.png", fine_checker(256));
  const Scene scene = renderer::parse_scene(
      scene_json(kFacingPlane, R"({"type": "diffuse", "albedo_texture": "checker.png"})"),
      dir.path() / "scene.json");
  for (const RenderResult &r : render_both(scene, 1)) {
    double sum = 0.0, squares = 0.0;
    int n = 0;
    for (int y = 18; y < 46; ++y)
      for (int x = 18; x < 46; ++x) {
        const double v = r.composite.at(x, y)[1];
        sum += v;
        squares += v * v;
        ++n;
      }
    const double mean = sum / n;
    const double sd = std::sqrt(std::max(0.0, squares / n - mean * mean));
    EXPECT_NEAR(mean, 0.5, 0.01);
    EXPECT_LT(sd, 0.02) << "the checker aliases";
  }
}

// Texture coordinates far outside the page, or not numbers at all, read its
// edge (texture.glsl clamps before converting to an integer, which would
// otherwise be undefined: the sanitizer build, with float-cast-overflow,
// holds that). Every textured
// triangle's coordinates are overwritten here: huge u and hugely negative v
// read the top-right quarter, NaN the top-left one.
TEST(TextureFiltering, CoordinatesFarOutsideThePageReadItsEdge) {
  test::ScratchDir dir;
  renderer::write_image(dir.path() / "page.png", quarters(64));
  const Scene scene = renderer::parse_scene(
      scene_json(kFacingPlane, R"({"type": "diffuse", "albedo_texture": "page.png"})"),
      dir.path() / "scene.json");
  struct Case {
    float u, v;
    glm::vec3 colour;
  };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const Case &c : {Case{1e30f, -1e30f, {0, 1, 0}}, Case{nan, nan, {1, 0, 0}}}) {
    renderer::CompiledScene compiled = renderer::compile_scene(scene);
    const auto word = [](float f) { return glm::floatBitsToUint(f); };
    for (std::size_t r = 0; r < 4; r += SURFACE_UV_TEXELS) { // the plane's two triangles
      compiled.surfaces[r] = glm::uvec4(word(c.u), word(c.v), word(c.u), word(c.v));
      compiled.surfaces[r + 1].x = word(c.u);
      compiled.surfaces[r + 1].y = word(c.v);
    }
    const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, 1);
    std::vector<RenderResult> results{renderer::render_cpu(compiled, frame)};
    if (test::have_vulkan()) {
      renderer::GpuTracer tracer;
      tracer.load(compiled);
      results.push_back(tracer.render(frame));
    }
    for (const RenderResult &r : results) {
      const glm::vec3 seen = pixel(r.composite, 32, 32);
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(seen[k], c.colour[k], 2e-3) << "u " << c.u << " channel " << k;
    }
  }
}

// The executors read textures alike: the quarters' edges and the fine
// checker, at 16 rays per pixel, agree between the GPU and the CPU reference
// far below the sampling noise.
TEST(TextureFiltering, BothExecutorsReadTheSameTexture) {
  CAMHEAD_REQUIRE_VULKAN();
  test::ScratchDir dir;
  renderer::write_image(dir.path() / "page.png", quarters(64));
  for (const char *object : {kFacingPlane, kBox}) {
    Scene scene = renderer::parse_scene(
        scene_json(object, R"({"type": "diffuse", "albedo_texture": "page.png"})"),
        dir.path() / "scene.json");
    const RenderResult cpu = test::render_cpu(scene, 16);
    const RenderResult gpu = test::render_gpu(scene, 16);
    scene.render.seed += 1;
    const RenderResult other = test::render_cpu(scene, 16);
    const double noise = test::rmse(cpu.composite, other.composite) / std::sqrt(2.0);
    EXPECT_GT(noise, 0.0); // the quarters' edges are sampled
    EXPECT_LT(test::rmse(cpu.composite, gpu.composite), 0.1 * noise);
  }
}

// What a wrong texture is told.
std::string refusal(const test::ScratchDir &dir, const std::string &object,
                    const std::string &material) {
  try {
    (void)renderer::parse_scene(scene_json(object, material), dir.path() / "scene.json");
  } catch (const renderer::SceneError &e) {
    return e.what();
  }
  return "accepted";
}

TEST(TextureErrors, AWrongTextureIsRefusedByFileAndField) {
  test::ScratchDir dir;
  renderer::write_image(dir.path() / "page.png", quarters(8));
  renderer::write_image(dir.path() / "wide.png", Image(4097, 1, 3));
  Image bright(2, 2, 3);
  bright.at(1, 0)[2] = 1.5f;
  renderer::write_image(dir.path() / "bright.exr", bright);
  const std::string textured = R"({"type": "diffuse", "albedo_texture": "page.png"})";
  const std::string sphere =
      R"({"type": "sphere", "center": [0, 0, -2], "radius": 0.5, "material": "page"})";

  EXPECT_NE(refusal(dir, kFacingPlane, R"({"type": "diffuse", "albedo_texture": "gone.png"})")
                .find("materials.page.albedo_texture"),
            std::string::npos);
  const std::string on_sphere = refusal(dir, sphere, textured);
  EXPECT_NE(on_sphere.find("objects[0].material"), std::string::npos) << on_sphere;
  EXPECT_NE(on_sphere.find("texture coordinates"), std::string::npos) << on_sphere;
  const std::string wide =
      refusal(dir, kFacingPlane, R"({"type": "diffuse", "albedo_texture": "wide.png"})");
  EXPECT_NE(wide.find("4097x1"), std::string::npos) << wide;
  const std::string too_bright =
      refusal(dir, kFacingPlane, R"({"type": "diffuse", "albedo_texture": "bright.exr"})");
  EXPECT_NE(too_bright.find("pixel (1, 0)"), std::string::npos) << too_bright;
  EXPECT_NE(refusal(dir, kFacingPlane, R"({"type": "diffuse"})").find("albedo"), std::string::npos);
  EXPECT_NE(refusal(dir, kFacingPlane, R"({"type": "mirror", "albedo_texture": "page.png"})")
                .find("albedo_texture"),
            std::string::npos);
  EXPECT_EQ(refusal(dir, kFacingPlane, textured), "accepted");
}

} // namespace
} // namespace camhead
