// Triangle meshes from OBJ (tinyobjloader, header-only) and PLY files.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

#include "camhead/renderer/scene.h"

namespace camhead::renderer {

class MeshError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// Polygons are fan-triangulated; normals and texture coordinates are ignored
// (the tracer shades with flat face normals, as Cycles does for these scenes).
// Throws MeshError naming the file (and the line or element where known).
// Files over 1 GiB are refused unread.
[[nodiscard]] TriangleMesh load_mesh(const std::filesystem::path &path);

// The same from the file's text; `path` picks the format by its extension
// and names the file in errors.
[[nodiscard]] TriangleMesh parse_mesh(const std::string &text, const std::filesystem::path &path);

} // namespace camhead::renderer
