// The scene model: what a scene file (docs: scene-format.md) describes, in
// plain values. One model for the GPU tracer and the CPU reference alike.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/image.h"

namespace camhead::renderer {

struct RenderSettings {
  int width = 720;
  int height = 576;
  int samples = 64; // rays per pixel
  std::uint32_t seed = 0;
  float pixel_filter_width_px = 1.0f; // box filter
  int max_bounces = 0;                // 0 = direct light only
  glm::vec3 world_color{0.0f};        // radiance of escaping rays
};

struct CameraDesc {
  glm::vec3 position{0.0f};
  glm::vec3 look_at{0.0f, 0.0f, -1.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float focal_length_mm = 35.0f;
  float sensor_width_mm = 36.0f;
  float f_number = 0.0f;         // 0 = pinhole
  float focus_distance_m = 0.0f; // depth of the focal plane along the axis
};

enum class MaterialType { diffuse, mirror, glass, emission };

struct Texture {
  std::shared_ptr<const Image> image; // none: no texture
  std::filesystem::path file;         // where it was read from
};

struct Material {
  std::string name;
  MaterialType type = MaterialType::diffuse;
  // albedo (diffuse), tint (mirror), radiance (emission); unused for glass
  glm::vec3 color{0.5f};
  float ior = 1.5f; // glass only
  // Diffuse only: an albedo image (linear, within [0, 1]) that `color`
  // multiplies, spread once over each face of a plane or box: its top-left
  // corner at a plane's own (-x, -z) corner, its top row along +x, seen from
  // above (+y) before the plane's rotation; upright on a box's sides seen
  // from outside, its top and bottom as a plane's (the bottom's seen from
  // below). Spheres and meshes have no texture coordinates (the scene
  // loader refuses a textured material on them).
  Texture albedo_texture;
};

// Triangles in the mesh's own frame, before scale / rotation / translation.
struct TriangleMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
};

enum class ShapeType { plane, box, sphere, mesh };

struct Object {
  std::string name;
  ShapeType type = ShapeType::sphere;
  glm::vec3 center{0.0f};
  glm::vec3 rotation_deg{0.0f};             // XYZ Euler, applied before translation
  glm::vec3 size{1.0f};                     // box: full extents; plane: (x, unused, z)
  float radius = 1.0f;                      // sphere
  float scale = 1.0f;                       // mesh, uniform
  std::shared_ptr<const TriangleMesh> mesh; // mesh only
  std::filesystem::path mesh_file;          // mesh only, resolved path
  int material = 0;                         // index into Scene::materials
  bool real = false;                        // part of the real-world proxy
};

enum class LightType { point, area, sun };

struct Light {
  std::string name;
  LightType type = LightType::point;
  glm::vec3 position{0.0f};               // point, area
  glm::vec3 normal{0.0f, -1.0f, 0.0f};    // area: front side (unit)
  glm::vec3 direction{0.0f, -1.0f, 0.0f}; // sun: direction of travel (unit)
  glm::vec2 size{1.0f};                   // area: full extents
  float power_W = 0.0f;                   // point, area
  float irradiance_W_m2 = 0.0f;           // sun
  glm::vec3 color{1.0f};
};

struct Scene {
  std::filesystem::path source; // the file it was read from, for messages
  RenderSettings render;
  CameraDesc camera;
  std::vector<Material> materials;
  std::vector<Object> objects;
  std::vector<Light> lights;
  std::optional<Image> plate;       // the camera image I_c, linear RGB
  std::filesystem::path plate_file; // where the plate was read from, if any
};

} // namespace camhead::renderer
