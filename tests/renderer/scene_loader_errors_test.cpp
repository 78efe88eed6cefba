// Malformed scenes: one variant per rule of the reference reader
// (blender_scene.py), each of which must fail with SceneError on the field the
// reference names; syntax errors; and damaged text, which must never get
// anything but a Scene or a SceneError out of the reader.
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "camhead/renderer/scene_loader.h"
#include "scene_json_fixture.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

namespace fs = std::filesystem;

struct BadCase {
  const char *what;
  std::function<void(Json &)> edit;
  const char *field;
};

// One variant per rule of the reference reader, in the order it checks.
const std::vector<BadCase> &bad_cases() {
  static const std::vector<BadCase> cases = {
      {"missing render", [](Json &j) { j.erase("render"); }, "render"},
      {"unknown top-level field", [](Json &j) { j["extra"] = 1; }, "extra"},
      {"render not an object", [](Json &j) { j["render"] = 3; }, "render"},
      {"unknown render field", [](Json &j) { j["render"]["spp"] = 3; }, "render.spp"},
      {"missing width", [](Json &j) { j["render"].erase("width"); }, "render.width"},
      {"width not an integer", [](Json &j) { j["render"]["width"] = 8.0; }, "render.width"},
      {"width as string", [](Json &j) { j["render"]["width"] = "8"; }, "render.width"},
      {"width as bool", [](Json &j) { j["render"]["width"] = true; }, "render.width"},
      {"width zero", [](Json &j) { j["render"]["width"] = 0; }, "render.width"},
      {"height too big", [](Json &j) { j["render"]["height"] = 65537; }, "render.height"},
      {"huge samples", [](Json &j) { j["render"]["samples"] = 1ull << 63; }, "render.samples"},
      {"negative seed", [](Json &j) { j["render"]["seed"] = -1; }, "render.seed"},
      {"seed too big", [](Json &j) { j["render"]["seed"] = 1ll << 31; }, "render.seed"},
      {"bounces too big", [](Json &j) { j["render"]["max_bounces"] = 1025; }, "render.max_bounces"},
      {"negative world",
       [](Json &j) {
         j["render"]["world_color"] = {0, -1, 0};
       },
       "render.world_color"},
      {"short world",
       [](Json &j) {
         j["render"]["world_color"] = {0, 0};
       },
       "render.world_color"},
      {"filter type",
       [](Json &j) {
         j["render"]["pixel_filter"] = {{"type", "GAUSSIAN"}};
       },
       "render.pixel_filter.type"},
      {"filter type missing", [](Json &j) { j["render"]["pixel_filter"] = Json::object(); },
       "render.pixel_filter.type"},
      {"filter width",
       [](Json &j) {
         j["render"]["pixel_filter"] = {{"type", "BOX"}, {"width_px", 0.001}};
       },
       "render.pixel_filter.width_px"},
      {"filter extra",
       [](Json &j) {
         j["render"]["pixel_filter"] = {{"type", "BOX"}, {"shape", 1}};
       },
       "render.pixel_filter.shape"},
      {"missing camera", [](Json &j) { j.erase("camera"); }, "camera"},
      {"camera extra", [](Json &j) { j["camera"]["fov"] = 40; }, "camera.fov"},
      {"position not array", [](Json &j) { j["camera"]["position"] = 0; }, "camera.position"},
      {"position with null",
       [](Json &j) {
         j["camera"]["position"] = {0, nullptr, 0};
       },
       "camera.position"},
      {"zero up",
       [](Json &j) {
         j["camera"]["up"] = {0, 0, 0};
       },
       "camera.up"},
      {"focal zero", [](Json &j) { j["camera"]["focal_length_mm"] = 0; }, "camera.focal_length_mm"},
      {"sensor too big", [](Json &j) { j["camera"]["sensor_width_mm"] = 1001; },
       "camera.sensor_width_mm"},
      {"sensor fit", [](Json &j) { j["camera"]["sensor_fit"] = "VERTICAL"; }, "camera.sensor_fit"},
      {"negative f_number", [](Json &j) { j["camera"]["f_number"] = -1; }, "camera.f_number"},
      {"look_at is position",
       [](Json &j) {
         j["camera"]["look_at"] = {0, 0.5, 0};
       },
       "camera.look_at"},
      {"up parallel",
       [](Json &j) {
         j["camera"]["up"] = {0, 0, -3};
       },
       "camera.up"},
      {"focus missing", [](Json &j) { j["camera"].erase("focus_distance_m"); },
       "camera.focus_distance_m"},
      {"focus zero on pinhole",
       [](Json &j) {
         j["camera"]["f_number"] = 0;
         j["camera"]["focus_distance_m"] = 0;
       },
       "camera.focus_distance_m"},
      {"plate not a string", [](Json &j) { j["plate"] = 1; }, "plate"},
      {"plate empty", [](Json &j) { j["plate"] = ""; }, "plate"},
      {"materials empty", [](Json &j) { j["materials"] = Json::object(); }, "materials"},
      {"materials array", [](Json &j) { j["materials"] = Json::array(); }, "materials"},
      {"material not object", [](Json &j) { j["materials"]["grey"] = 1; }, "materials.grey.type"},
      {"material type", [](Json &j) { j["materials"]["grey"]["type"] = "metal"; },
       "materials.grey.type"},
      {"albedo above one",
       [](Json &j) {
         j["materials"]["grey"]["albedo"] = {1.5, 0, 0};
       },
       "materials.grey.albedo"},
      {"albedo missing", [](Json &j) { j["materials"]["grey"].erase("albedo"); },
       "materials.grey.albedo"},
      {"diffuse with tint",
       [](Json &j) {
         j["materials"]["grey"]["tint"] = {1, 1, 1};
       },
       "materials.grey.tint"},
      {"ior below one", [](Json &j) { j["materials"]["glass"]["ior"] = 0.9; },
       "materials.glass.ior"},
      {"negative radiance",
       [](Json &j) {
         j["materials"]["lamp"]["radiance"] = {-1, 0, 0};
       },
       "materials.lamp.radiance"},
      {"objects not array", [](Json &j) { j["objects"] = Json::object(); }, "objects"},
      {"object not object", [](Json &j) { j["objects"][1] = 5; }, "objects[1].type"},
      {"object type", [](Json &j) { j["objects"][1]["type"] = "cone"; }, "objects[1].type"},
      {"sphere without center", [](Json &j) { j["objects"][2].erase("center"); },
       "objects[2].center"},
      {"sphere with size",
       [](Json &j) {
         j["objects"][2]["size"] = {1, 1, 1};
       },
       "objects[2].size"},
      {"scale on a box", [](Json &j) { j["objects"][1]["scale"] = 2; }, "objects[1].scale"},
      {"empty name", [](Json &j) { j["objects"][2]["name"] = ""; }, "objects[2].name"},
      {"duplicate name", [](Json &j) { j["objects"][2]["name"] = "box1"; }, "objects[2].name"},
      {"unknown material", [](Json &j) { j["objects"][1]["material"] = "gold"; },
       "objects[1].material"},
      {"real as int", [](Json &j) { j["objects"][0]["real"] = 1; }, "objects[0].real"},
      {"plane size of 3",
       [](Json &j) {
         j["objects"][0]["size"] = {1, 1, 1};
       },
       "objects[0].size"},
      {"box size zero",
       [](Json &j) {
         j["objects"][1]["size"] = {1, 0, 1};
       },
       "objects[1].size"},
      {"sphere radius zero", [](Json &j) { j["objects"][2]["radius"] = 0; }, "objects[2].radius"},
      {"radius overflow", [](Json &j) { j["objects"][2]["radius"] = 1e300; }, "objects[2].radius"},
      {"center beyond float",
       [](Json &j) {
         j["objects"][2]["center"] = {0, 1e300, 0};
       },
       "objects[2].center"},
      {"mesh without file",
       [](Json &j) {
         j["objects"].push_back({{"type", "mesh"}, {"material", "grey"}});
       },
       "objects[3].file"},
      {"mesh bad extension",
       [](Json &j) {
         j["objects"].push_back({{"type", "mesh"}, {"file", "a.stl"}, {"material", "grey"}});
       },
       "objects[3].file"},
      {"mesh missing file",
       [](Json &j) {
         j["objects"].push_back({{"type", "mesh"}, {"file", "nope.obj"}, {"material", "grey"}});
       },
       "objects[3].file"},
      {"mesh scale zero",
       [](Json &j) {
         j["objects"].push_back(
             {{"type", "mesh"}, {"file", "a.obj"}, {"material", "grey"}, {"scale", 0}});
       },
       "objects[3].scale"},
      {"lights not array", [](Json &j) { j["lights"] = 1; }, "lights"},
      {"light type", [](Json &j) { j["lights"][0]["type"] = "spot"; }, "lights[0].type"},
      {"point with normal",
       [](Json &j) {
         j["lights"][0]["normal"] = {0, 1, 0};
       },
       "lights[0].normal"},
      {"negative power", [](Json &j) { j["lights"][0]["power_W"] = -1; }, "lights[0].power_W"},
      {"negative color",
       [](Json &j) {
         j["lights"][0]["color"] = {1, -1, 1};
       },
       "lights[0].color"},
      {"area size zero",
       [](Json &j) {
         j["lights"][1]["size"] = {0, 1};
       },
       "lights[1].size"},
      {"area normal zero",
       [](Json &j) {
         j["lights"][1]["normal"] = {0, 0, 0};
       },
       "lights[1].normal"},
      {"sun direction missing", [](Json &j) { j["lights"][2].erase("direction"); },
       "lights[2].direction"},
      {"sun irradiance", [](Json &j) { j["lights"][2]["irradiance_W_m2"] = "3"; },
       "lights[2].irradiance_W_m2"},
  };
  return cases;
}

TEST(SceneLoaderErrors, RejectsEachMalformedVariantOnItsField) {
  for (const BadCase &c : bad_cases()) {
    Json j = base_scene();
    c.edit(j);
    try {
      (void)parse(j);
      ADD_FAILURE() << c.what << ": accepted";
    } catch (const SceneError &e) {
      EXPECT_EQ(e.field(), c.field) << c.what << ": " << e.what();
      EXPECT_FALSE(e.reason().empty()) << c.what;
    }
  }
}

TEST(SceneLoaderErrors, NonFiniteLiteralsFailOnTheirField) {
  // Python's json reads these literals (and 1e999 as inf); the reference then
  // rejects the value.
  for (const char *literal : {"NaN", "Infinity", "-Infinity", "1e999"}) {
    std::string text = base_scene().dump();
    const std::string key = "\"radius\":0.2";
    text.replace(text.find(key), key.size(), std::string("\"radius\":") + literal);
    try {
      (void)parse_scene(text, "s.json");
      ADD_FAILURE() << literal << " accepted";
    } catch (const SceneError &e) {
      EXPECT_EQ(e.field(), "objects[2].radius") << e.what();
      EXPECT_EQ(e.reason(), "must be a finite number");
    }
  }
  // Inside a string they are just text.
  Json j = base_scene();
  j["objects"][2]["name"] = "NaN Infinity";
  EXPECT_EQ(parse(j).objects[2].name, "NaN Infinity");
}

TEST(SceneLoaderErrors, SyntaxErrorsNameTheLineAndColumn) {
  const std::string text = "{\n  \"render\": {\"width\": 8,\n  \"height\": ]\n}";
  try {
    (void)parse_scene(text, "broken.json");
    FAIL() << "accepted broken JSON";
  } catch (const SceneError &e) {
    EXPECT_EQ(e.file(), "broken.json");
    EXPECT_NE(e.reason().find("line 3, column 13"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("broken.json: ", 0), 0u) << e.what();
  }
  EXPECT_THROW((void)parse_scene("", "empty.json"), SceneError);
  EXPECT_THROW((void)parse_scene("[1, 2]", "array.json"), SceneError);
  EXPECT_THROW((void)parse_scene("\xEF\xBB\xBF{}", "bom.json"), SceneError);
  EXPECT_THROW((void)load_scene("/nonexistent/scene.json"), SceneError);
  EXPECT_THROW((void)load_scene(kAssets), SceneError); // a directory
}

TEST(SceneLoaderErrors, NeverCrashesOnTruncatedOrCorruptedText) {
  const std::string text = base_scene().dump(1);
  for (std::size_t n = 0; n < text.size(); ++n)
    EXPECT_THROW((void)parse_scene(text.substr(0, n), "cut.json"), SceneError) << n;
  // Byte flips must give a scene or a SceneError, nothing else.
  for (std::size_t i = 0; i < text.size(); ++i) {
    for (const char c : {'0', '"', '[', '}', ',', '-', 'e', '\0', '\xff'}) {
      std::string t = text;
      t[i] = c;
      try {
        (void)parse_scene(t, "flip.json");
      } catch (const SceneError &) {
      }
    }
  }
  EXPECT_THROW((void)parse_scene(std::string(100000, '['), "deep.json"), SceneError);
}

} // namespace
} // namespace camhead::renderer
