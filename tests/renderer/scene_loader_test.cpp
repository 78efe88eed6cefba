// The scene reader against the reference scenes, the defaults of the
// reference reader (blender_scene.py), and one malformed variant per rule:
// each must fail with SceneError on the field the reference names.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "camhead/renderer/image_io.h"
#include "camhead/renderer/scene_loader.h"
#include "scene_json_fixture.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

namespace fs = std::filesystem;

TEST(SceneLoader, LoadsBoxesReference) {
  const Scene s = load_scene(test::reference_dir() / "boxes.json");
  EXPECT_EQ(s.render.width, 720);
  EXPECT_EQ(s.render.height, 576);
  EXPECT_EQ(s.render.samples, 64);
  EXPECT_EQ(s.render.seed, 0u);
  EXPECT_EQ(s.render.max_bounces, 0);
  EXPECT_FLOAT_EQ(s.render.pixel_filter_width_px, 1.0f);
  EXPECT_EQ(s.camera.position, glm::vec3(0.0f, 0.5f, 0.0f));
  EXPECT_EQ(s.camera.look_at, glm::vec3(0.0f, 0.5f, -1.0f));
  EXPECT_FLOAT_EQ(s.camera.focal_length_mm, 35.0f);
  EXPECT_FLOAT_EQ(s.camera.sensor_width_mm, 36.0f);
  EXPECT_FLOAT_EQ(s.camera.f_number, 1.8f);
  EXPECT_FLOAT_EQ(s.camera.focus_distance_m, 1.5f);
  ASSERT_EQ(s.materials.size(), 4u);
  const char *names[] = {"ground", "red", "green", "blue"}; // file order, not sorted
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(s.materials[i].name, names[i]);
  EXPECT_EQ(s.materials[1].color, glm::vec3(0.7f, 0.08f, 0.05f));
  ASSERT_EQ(s.objects.size(), 4u);
  EXPECT_EQ(s.objects[0].type, ShapeType::plane);
  EXPECT_EQ(s.objects[0].size, glm::vec3(20.0f, 1.0f, 20.0f));
  EXPECT_TRUE(s.objects[0].real);
  EXPECT_EQ(s.objects[1].name, "box_near");
  EXPECT_EQ(s.objects[1].type, ShapeType::box);
  EXPECT_EQ(s.objects[1].material, 1);
  EXPECT_EQ(s.objects[1].size, glm::vec3(0.08f, 0.45f, 0.08f));
  EXPECT_EQ(s.objects[3].material, 3);
  EXPECT_EQ(s.objects[3].center, glm::vec3(-0.4f, 0.3f, -4.3f));
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, LightType::point);
  EXPECT_FLOAT_EQ(s.lights[0].power_W, 200.0f);
  EXPECT_EQ(s.lights[0].position, glm::vec3(0.8f, 2.5f, 0.5f));
  EXPECT_FALSE(s.plate.has_value());
}

TEST(SceneLoader, LoadsArBasicReferenceWithPlate) {
  const Scene s = load_scene(test::reference_dir() / "ar_basic.json");
  EXPECT_EQ(s.render.samples, 1024);
  EXPECT_FLOAT_EQ(s.camera.f_number, 2.0f);
  EXPECT_FLOAT_EQ(s.camera.focus_distance_m, 2.0f);
  ASSERT_EQ(s.objects.size(), 4u);
  EXPECT_EQ(s.objects[1].rotation_deg, glm::vec3(0.0f, 25.0f, 0.0f));
  EXPECT_EQ(s.objects[2].type, ShapeType::sphere);
  EXPECT_FLOAT_EQ(s.objects[2].radius, 0.25f);
  EXPECT_FALSE(s.objects[2].real);
  EXPECT_EQ(s.objects[2].material, 2);
  EXPECT_EQ(s.objects[3].rotation_deg, glm::vec3(20.0f, 35.0f, 0.0f));
  ASSERT_TRUE(s.plate.has_value());
  EXPECT_EQ(s.plate->width, 720);
  EXPECT_EQ(s.plate->height, 576);
  EXPECT_EQ(s.plate->channels, 3);
  // Same pixels as reading the plate directly.
  EXPECT_EQ(s.plate->data, read_image(test::reference_dir() / "ar_basic_plate.exr").data);
}

TEST(SceneLoader, FillsTheReferenceDefaults) {
  const Scene s = parse(base_scene());
  EXPECT_EQ(s.source, fs::path("/virtual/scene.json"));
  EXPECT_EQ(s.render.seed, 0u);
  EXPECT_EQ(s.render.max_bounces, 0);
  EXPECT_FLOAT_EQ(s.render.pixel_filter_width_px, 1.0f);
  EXPECT_EQ(s.render.world_color, glm::vec3(0.0f));
  EXPECT_EQ(s.camera.up, glm::vec3(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(s.materials[1].type, MaterialType::mirror);
  EXPECT_EQ(s.materials[1].color, glm::vec3(1.0f)); // default tint
  EXPECT_EQ(s.materials[2].type, MaterialType::glass);
  EXPECT_FLOAT_EQ(s.materials[2].ior, 1.5f);
  EXPECT_EQ(s.materials[3].color, glm::vec3(2.0f));
  EXPECT_EQ(s.objects[0].name, "plane0"); // <type><index>
  EXPECT_EQ(s.objects[1].name, "box1");
  EXPECT_EQ(s.objects[2].name, "ball");
  EXPECT_FALSE(s.objects[1].real);
  EXPECT_EQ(s.objects[1].rotation_deg, glm::vec3(0.0f));
  EXPECT_EQ(s.objects[1].material, 2);
  EXPECT_EQ(s.lights[0].name, "light0");
  EXPECT_EQ(s.lights[0].color, glm::vec3(1.0f));
  EXPECT_EQ(s.lights[1].type, LightType::area);
  EXPECT_EQ(s.lights[1].size, glm::vec2(1.0f, 2.0f));
  EXPECT_EQ(s.lights[1].normal, glm::vec3(0.0f, -1.0f, 0.0f)); // normalised
  EXPECT_NEAR(s.lights[2].direction.y, -0.6f, 1e-7f);
  EXPECT_NEAR(s.lights[2].direction.z, -0.8f, 1e-7f);
  EXPECT_FLOAT_EQ(s.lights[2].irradiance_W_m2, 3.0f);

  Json j = base_scene();
  j["lights"][1]["normal"] = {0, 0, 1e-300}; // tiny but not zero: a direction
  EXPECT_EQ(parse(j).lights[1].normal, glm::vec3(0.0f, 0.0f, 1.0f));
  j["camera"].erase("f_number");
  j["camera"].erase("focus_distance_m");
  EXPECT_FLOAT_EQ(parse(j).camera.f_number, 0.0f); // pinhole needs no focus
}

TEST(SceneLoader, LoadsMeshesRelativeToTheSceneFile) {
  const Scene s = load_scene(kAssets / "mesh_scene.json");
  ASSERT_EQ(s.objects.size(), 3u);
  EXPECT_EQ(s.objects[0].name, "mesh0");
  EXPECT_EQ(s.objects[0].mesh_file, kAssets / "quad.obj");
  ASSERT_TRUE(s.objects[0].mesh);
  EXPECT_EQ(s.objects[0].mesh->triangles.size(), 3u);
  EXPECT_FLOAT_EQ(s.objects[0].scale, 1.0f);
  EXPECT_EQ(s.objects[1].mesh->triangles.size(), 3u);
  EXPECT_FLOAT_EQ(s.objects[1].scale, 0.5f);
  EXPECT_EQ(s.objects[1].center, glm::vec3(1.0f, 0.0f, 0.0f));
  // The same file named another way is loaded once and shared.
  EXPECT_EQ(s.objects[2].mesh, s.objects[0].mesh);
  EXPECT_TRUE(s.objects[2].real);
}

// Python's json + dict (the reference reader) would keep the last of two
// keys without a word; camhead names the one given twice.
TEST(SceneLoader, AKeyGivenTwiceIsRefusedOnItsField) {
  const std::string text = R"({"render": {"width": 1, "height": 1, "samples": 1},
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "focal_length_mm": 35,
               "sensor_width_mm": 36},
    "materials": {"a": {"type": "mirror"}, "b": {"type": "mirror"},
                  "a": {"type": "glass", "ior": 1.2}},
    "objects": [{"type": "sphere", "center": [0, 0, -1], "radius": 1, "material": "b"}]})";
  try {
    (void)parse_scene(text, "dup.json");
    FAIL() << "accepted a material given twice";
  } catch (const SceneError &e) {
    EXPECT_EQ(e.field(), "materials.a");
    EXPECT_EQ(e.reason(), "given twice in one object; only one would count: give it once");
  }
  // The fuzzer's: an empty key twice, named as JSON spells it, not blank.
  try {
    (void)load_scene(std::filesystem::path(CAMHEAD_SOURCE_DIR) /
                     "tests/assets/fuzz/scene_empty_key_twice.json");
    FAIL() << "accepted an empty key given twice";
  } catch (const SceneError &e) {
    EXPECT_EQ(e.field(), "\"\"");
  }
}

// A camera whose axes the tracer cannot build in float32 is refused, not
// rendered as a frame of nothing: an up whose square overflows, a target
// whose distance's square does.
TEST(SceneLoader, ACameraWithoutAxesInFloatIsRefused) {
  for (const auto &[camera, field] :
       {std::pair{R"("position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1e20, 0])", "up"},
        std::pair{R"("position": [0, 0, 0], "look_at": [0, 0, -1e20])", "look_at"}}) {
    const std::string text = std::string(R"({"render": {"width": 1, "height": 1, "samples": 1},
      "camera": {)") + camera +
                             R"(, "focal_length_mm": 35, "sensor_width_mm": 36},
      "materials": {"a": {"type": "mirror"}},
      "objects": [{"type": "sphere", "center": [0, 0, -1], "radius": 1, "material": "a"}]})";
    try {
      (void)parse_scene(text, "far.json");
      ADD_FAILURE() << "accepted " << camera;
    } catch (const SceneError &e) {
      EXPECT_EQ(e.field(), std::string("camera.") + field) << camera;
    }
  }
}

TEST(SceneLoader, ErrorNamesFileFieldAndReason) {
  Json j = base_scene();
  j["objects"][2]["radius"] = -1;
  try {
    (void)parse(j);
    FAIL() << "accepted a negative radius";
  } catch (const SceneError &e) {
    EXPECT_EQ(e.file(), "/virtual/scene.json");
    EXPECT_EQ(e.field(), "objects[2].radius");
    EXPECT_EQ(e.reason(), "must be > 0 and <= 1e+06");
    EXPECT_STREQ(e.what(), "/virtual/scene.json: objects[2].radius: must be > 0 and <= 1e+06");
  }
}

class SceneLoaderFiles : public ::testing::Test {
protected:
  void write(const std::string &name, const std::string &text) const {
    (void)scratch_.write(name, text);
  }
  SceneError load_error(const Json &j) const {
    write("scene.json", j.dump());
    try {
      (void)load_scene(dir_ / "scene.json");
    } catch (const SceneError &e) {
      return e;
    }
    ADD_FAILURE() << "scene accepted";
    return SceneError("", "", "");
  }

  test::ScratchDir scratch_;
  const fs::path dir_ = scratch_.path();
};

TEST_F(SceneLoaderFiles, BadMeshFileFailsOnTheFileField) {
  write("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
  Json j = base_scene();
  j["objects"].push_back({{"type", "mesh"}, {"file", "bad.obj"}, {"material", "grey"}});
  const SceneError e = load_error(j);
  EXPECT_EQ(e.field(), "objects[3].file");
  EXPECT_NE(e.reason().find((dir_ / "bad.obj").string()), std::string::npos) << e.what();

  write("cut.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n");
  j["objects"][3]["file"] = "cut.ply";
  EXPECT_EQ(load_error(j).field(), "objects[3].file");
}

TEST_F(SceneLoaderFiles, PlateIsLoadedAndMustMatchTheRenderSize) {
  write_image(dir_ / "plate.exr", Image(8, 6, 3));
  write_image(dir_ / "small.exr", Image(4, 3, 3));
  Json j = base_scene();
  j["plate"] = "plate.exr";
  write("scene.json", j.dump());
  const Scene s = load_scene(dir_ / "scene.json");
  ASSERT_TRUE(s.plate.has_value());
  EXPECT_EQ(s.plate->width, 8);

  j["plate"] = "small.exr";
  SceneError e = load_error(j);
  EXPECT_EQ(e.field(), "plate");
  EXPECT_NE(e.reason().find("4x3"), std::string::npos) << e.what();

  j["plate"] = "missing.exr";
  e = load_error(j);
  EXPECT_EQ(e.field(), "plate");
  EXPECT_NE(e.reason().find("missing.exr"), std::string::npos) << e.what();
}

} // namespace
} // namespace camhead::renderer
