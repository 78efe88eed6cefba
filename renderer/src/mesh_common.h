// What the OBJ and PLY readers share: the error they throw, reading the
// file and triangulating a polygon. Private to the renderer.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "camhead/renderer/mesh_io.h"

namespace camhead::renderer::detail {

[[noreturn]] inline void fail(const std::filesystem::path &path, const std::string &reason) {
  throw MeshError(path.string() + ": " + reason);
}

inline std::string read_file(const std::filesystem::path &path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    fail(path, "cannot open");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad())
    fail(path, "read error");
  return bytes;
}

// Fan triangulation of one polygon, as the header promises; polygons with
// fewer than three corners carry no area and are dropped, as tinyobjloader
// does.
inline void add_polygon(TriangleMesh &mesh, const std::vector<std::uint32_t> &corners) {
  for (std::size_t k = 1; k + 1 < corners.size(); ++k)
    mesh.triangles.emplace_back(corners[0], corners[k], corners[k + 1]);
}

} // namespace camhead::renderer::detail
