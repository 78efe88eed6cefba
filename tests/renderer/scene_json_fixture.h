// The scene-reader tests' starting point: a small valid scene with every kind
// of material, object and light, as JSON to be broken one field at a time.
#pragma once

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "camhead/renderer/scene_loader.h"

namespace camhead::renderer {

using Json = nlohmann::ordered_json;

inline const std::filesystem::path kAssets =
    std::filesystem::path(CAMHEAD_SOURCE_DIR) / "tests" / "assets";

inline Json base_scene() {
  std::ifstream in(kAssets / "all_kinds.json");
  return Json::parse(in);
}

inline Scene parse(const Json &j) {
  return parse_scene(j.dump(), "/virtual/scene.json");
}

} // namespace camhead::renderer
