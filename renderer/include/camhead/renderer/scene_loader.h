// Reads scene files (JSON, scene-format.md version 1) into the scene model.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "camhead/base/config_error.h"
#include "camhead/renderer/scene.h"

namespace camhead::renderer {

// A scene file that cannot be used. what() reads "FILE: FIELD: REASON", where
// FIELD is a JSON path such as objects[2].radius (base/config_error.h).
class SceneError : public base::ConfigError {
public:
  using base::ConfigError::ConfigError;
  explicit SceneError(const base::ConfigError &e) : base::ConfigError(e) {}
};

// Loads a scene with its meshes and plate. Throws SceneError on any problem
// (unknown field, wrong type, out-of-range value, unreadable mesh or plate).
[[nodiscard]] Scene load_scene(const std::filesystem::path &path);

// Parses scene JSON text; relative mesh and plate paths resolve against
// source.parent_path(). Throws SceneError naming `source`.
[[nodiscard]] Scene parse_scene(std::string_view json_text, const std::filesystem::path &source);

} // namespace camhead::renderer
