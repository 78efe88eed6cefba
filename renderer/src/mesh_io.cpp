// OBJ goes through tinyobjloader, compiled into this file only so that the
// renderer needs no shared library for it; PLY has its own reader in
// ply_reader.cpp.
#include "camhead/renderer/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>

#include "camhead/base/input_file.h"
#include "mesh_common.h"
#include "ply_reader.h"

namespace camhead::renderer {
namespace {

using Path = std::filesystem::path;
using detail::add_polygon;
using detail::fail;

// 2^24 corners (kMaxObjCorners) written as OBJ text take well under this.
constexpr std::size_t kMaxMeshFileBytes = std::size_t(1) << 30;

enum class MeshType { obj, ply, unknown };

MeshType mesh_type(const Path &path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".obj" ? MeshType::obj : ext == ".ply" ? MeshType::ply : MeshType::unknown;
}

void validate(const Path &path, const TriangleMesh &mesh) {
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::vec3 &p = mesh.positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      fail(path, "vertex " + std::to_string(i) + " is not a finite point");
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::uvec3 &tri = mesh.triangles[t];
    if (std::max({tri.x, tri.y, tri.z}) >= mesh.positions.size()) {
      fail(path, "triangle " + std::to_string(t) + " references a vertex beyond the " +
                     std::to_string(mesh.positions.size()) + " in the file");
    }
  }
  if (mesh.triangles.empty())
    fail(path, "contains no faces");
}

// ------------------------------------------------------------------ OBJ

// tinyobjloader accumulates decimal exponents in an int and overflows (UB)
// past nine digits; no real mesh has such numbers, so refuse them up front.
void check_exponents(const Path &path, const std::string &text) {
  int line = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n')
      ++line;
    if ((text[i] != 'e' && text[i] != 'E') || i == 0 ||
        !(std::isdigit((unsigned char)text[i - 1]) || text[i - 1] == '.'))
      continue;
    std::size_t j = i + 1;
    if (j < text.size() && (text[j] == '+' || text[j] == '-'))
      ++j;
    while (j < text.size() && text[j] == '0')
      ++j;
    std::size_t digits = 0;
    for (; j < text.size() && std::isdigit((unsigned char)text[j]); ++j)
      ++digits;
    if (digits > 6)
      fail(path, "line " + std::to_string(line) + ": number exponent out of range");
  }
}

// Corners (face vertex references) an OBJ may have: 16 M, about 5.6 M
// triangles, a few hundred MB inside tinyobjloader.
constexpr std::size_t kMaxObjCorners = std::size_t(1) << 24;

// Lines end as tinyobjloader ends them: at "\n", "\r\n" or a lone "\r".
// A filter that split at "\n" alone let a `vw` line through behind a "\r"
// (tests/fuzz/obj_fuzz).
std::size_t line_end(const std::string &text, std::size_t at) {
  return std::min(text.find_first_of("\r\n", at), text.size());
}
std::size_t next_line(const std::string &text, std::size_t end) {
  return end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
}

// The lines of an OBJ that make a triangle mesh, as tinyobjloader is given
// them: positions, and faces with their vertex indices alone. The rest
// (normals, texture coordinates, vertex weights, whose `vw c 1e60` makes
// tinyobjloader convert an out-of-range float to int, materials, groups) is
// left out; every face index is checked against the positions, and the
// corners against kMaxObjCorners, so that a garbage face is refused at its
// line before anything is stored for it.
std::string mesh_lines(const Path &path, const std::string &text) {
  std::size_t positions = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = line_end(text, at);
    if (end - at > 2 && text[at] == 'v' && (text[at + 1] == ' ' || text[at + 1] == '\t'))
      ++positions;
    at = next_line(text, end);
  }
  std::string out;
  std::size_t corners = 0, seen = 0;
  int line = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = line_end(text, at);
    ++line;
    std::string_view row(text.data() + at, end - at);
    at = next_line(text, end);
    while (!row.empty() && std::isspace((unsigned char)row.front()))
      row.remove_prefix(1);
    const bool blank_after = row.size() > 1 && (row[1] == ' ' || row[1] == '\t');
    if (row.size() < 2 || !blank_after || (row[0] != 'v' && row[0] != 'f'))
      continue;
    const std::string where = "line " + std::to_string(line) + ": ";
    if (row[0] == 'v') {
      ++seen;
      out.append(row);
      out += '\n';
      continue;
    }
    out += 'f';
    std::size_t i = 1;
    while (i < row.size()) {
      while (i < row.size() && std::isspace((unsigned char)row[i]))
        ++i;
      if (i >= row.size())
        break;
      const std::size_t token = i;
      while (i < row.size() && !std::isspace((unsigned char)row[i]))
        ++i;
      std::string_view vertex = row.substr(token, i - token);
      vertex = vertex.substr(0, vertex.find('/'));
      long long index = 0;
      const auto [ptr, ec] = std::from_chars(vertex.data(), vertex.data() + vertex.size(), index);
      if (ec != std::errc() || ptr != vertex.data() + vertex.size() || index == 0)
        fail(path, where + "face vertex '" + std::string(vertex.substr(0, 20)) +
                       "' is not a vertex index");
      // Negative: relative to the positions so far; positive: any position.
      const long long resolved = index < 0 ? (long long)seen + index + 1 : index;
      if (resolved < 1 || resolved > (long long)positions)
        fail(path, where + "face vertex " + std::to_string(index) + " is not one of the " +
                       std::to_string(index < 0 ? seen : positions) + " positions");
      if (++corners > kMaxObjCorners)
        fail(path, where + "more than " + std::to_string(kMaxObjCorners) + " face corners");
      out += ' ';
      out += std::to_string(resolved);
    }
    out += '\n';
  }
  return out;
}

TriangleMesh parse_obj(const Path &path, const std::string &text) {
  check_exponents(path, text);
  std::istringstream stream(mesh_lines(path, text));
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  // No material reader: following `mtllib` would open files the scene never named.
  if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &stream, nullptr,
                        /*triangulate=*/false, /*default_vcols_fallback=*/false)) {
    while (!err.empty() && std::isspace((unsigned char)err.back()))
      err.pop_back();
    fail(path, err.empty() ? "cannot parse OBJ" : err);
  }
  TriangleMesh mesh;
  mesh.positions.reserve(attrib.vertices.size() / 3);
  for (std::size_t i = 0; i + 2 < attrib.vertices.size(); i += 3)
    mesh.positions.emplace_back(attrib.vertices[i], attrib.vertices[i + 1], attrib.vertices[i + 2]);
  std::vector<std::uint32_t> corners;
  for (const tinyobj::shape_t &shape : shapes) {
    const auto &counts = shape.mesh.num_face_vertices;
    // Corner counts are stored in a byte, so a face with more than 255
    // corners desynchronises the index list.
    if (std::accumulate(counts.begin(), counts.end(), std::size_t(0)) != shape.mesh.indices.size())
      fail(path, "a face has more than 255 corners");
    std::size_t next = 0;
    for (const unsigned char n : counts) {
      corners.clear();
      // A negative (unresolved) index wraps to a huge one, which validate() rejects.
      for (std::size_t k = 0; k < n; ++k)
        corners.push_back(std::uint32_t(shape.mesh.indices[next + k].vertex_index));
      next += n;
      add_polygon(mesh, corners);
    }
  }
  return mesh;
}

} // namespace

TriangleMesh parse_mesh(const std::string &text, const std::filesystem::path &path) {
  TriangleMesh mesh;
  switch (mesh_type(path)) {
  case MeshType::obj:
    mesh = parse_obj(path, text);
    break;
  case MeshType::ply:
    mesh = detail::parse_ply(path, text);
    break;
  case MeshType::unknown:
    fail(path, "unsupported mesh type (expected .obj or .ply)");
  }
  validate(path, mesh);
  return mesh;
}

TriangleMesh load_mesh(const std::filesystem::path &path) {
  if (mesh_type(path) == MeshType::unknown)
    fail(path, "unsupported mesh type (expected .obj or .ply)");
  std::string error;
  const std::optional<std::string> text = base::read_input_file(path, kMaxMeshFileBytes, error);
  if (!text)
    fail(path, error);
  return parse_mesh(*text, path);
}

} // namespace camhead::renderer
