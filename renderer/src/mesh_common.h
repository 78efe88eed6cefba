// What the OBJ and PLY readers share: the error they throw and
// triangulating a polygon. Private to the renderer.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "camhead/renderer/mesh_io.h"

namespace camhead::renderer::detail {

[[noreturn]] inline void fail(const std::filesystem::path &path, const std::string &reason) {
  throw MeshError(path.string() + ": " + reason);
}

// Fan triangulation of one polygon, as the header promises; polygons with
// fewer than three corners carry no area and are dropped, as tinyobjloader
// does.
inline void add_polygon(TriangleMesh &mesh, const std::vector<std::uint32_t> &corners) {
  for (std::size_t k = 1; k + 1 < corners.size(); ++k)
    mesh.triangles.emplace_back(corners[0], corners[k], corners[k + 1]);
}

} // namespace camhead::renderer::detail
