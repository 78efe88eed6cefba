// The scene model flattened into the kernels' buffers. The geometric
// conventions are those of reference/blender_scene.py (trs, look_at_matrix,
// add_object, add_light) in camhead's own frame (Y up, camera down -Z), so
// that camhead and the Cycles references see the same scene.
#include "camhead/renderer/compiled_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/packing.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/bvh.h"

namespace camhead::renderer {
namespace {

constexpr float kPi = 3.14159265358979323846f;

// Blender's Euler 'XYZ': about X first, then Y, then Z, i.e. R = Rz Ry Rx on
// column vectors (mathutils Euler.to_matrix, used by trs()).
glm::mat3 euler_xyz(const glm::vec3 &degrees) {
  const glm::vec3 r = glm::radians(degrees);
  const float cx = std::cos(r.x), sx = std::sin(r.x);
  const float cy = std::cos(r.y), sy = std::sin(r.y);
  const float cz = std::cos(r.z), sz = std::sin(r.z);
  // glm matrices are built column by column.
  const glm::mat3 rx(1, 0, 0, 0, cx, sx, 0, -sx, cx);
  const glm::mat3 ry(cy, 0, -sy, 0, 1, 0, sy, 0, cy);
  const glm::mat3 rz(cz, sz, 0, -sz, cz, 0, 0, 0, 1);
  return rz * ry * rx;
}

// translate * rotate * scale, as trs() composes them.
struct Transform {
  glm::mat3 linear;
  glm::vec3 translation;

  Transform(const glm::vec3 &center, const glm::vec3 &rotation_deg, const glm::vec3 &scale)
      : linear(euler_xyz(rotation_deg) * glm::mat3(scale.x, 0, 0, 0, scale.y, 0, 0, 0, scale.z)),
        translation(center) {}
  [[nodiscard]] glm::vec3 operator()(const glm::vec3 &p) const { return linear * p + translation; }
};

std::uint32_t primitive_bits(const Object &o, std::uint32_t kind) {
  if (o.material < 0 || std::uint32_t(o.material) > PRIM_MATERIAL_MASK)
    throw std::invalid_argument("object " + o.name + ": material index " +
                                std::to_string(o.material) + " does not fit the primitive");
  return std::uint32_t(o.material) | (o.real ? PRIM_REAL_BIT : 0u) | kind << 24;
}

bool finite(const glm::vec3 &v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Degenerate and non-finite triangles are dropped: a NaN would poison the BVH
// bounds, and a zero-area triangle should hit nothing, but once transformed
// in float, collinear vertices keep a sliver of area at rounding level that
// the kernel's intersection could hit with a noise normal. Hence a relative
// test: edges less than about 1e-6 rad apart count as collinear.
void add_triangle(std::vector<gpu::Primitive> &out, const glm::vec3 &a, const glm::vec3 &b,
                  const glm::vec3 &c, std::uint32_t bits) {
  const glm::vec3 e1 = b - a, e2 = c - a;
  const float sine_bound = 1e-6f * glm::length(e1) * glm::length(e2);
  if (!finite(a) || !finite(e1) || !finite(e2) || !(glm::length(glm::cross(e1, e2)) > sine_bound))
    return;
  out.push_back(gpu::Primitive{gpu::vec4(a, glm::uintBitsToFloat(bits)), gpu::vec4(e1, 0.0f),
                               gpu::vec4(e2, 0.0f)});
}

// Where the triangles of a textured object put their texture coordinates
// (layout.h, BINDING_SURFACES); null for an untextured one.
using UvRecords = std::vector<glm::uvec4>;

// The triangle just added, if `out` grew past `before` (a degenerate one is
// dropped), gets the texture coordinates uv[0..2] at its three vertices.
void add_uv_record(std::vector<gpu::Primitive> &out, std::size_t before, UvRecords *records,
                   const std::array<glm::vec2, 3> &uv) {
  if (!records || out.size() == before)
    return;
  gpu::Primitive &p = out.back();
  const float area_m2 = glm::length(glm::cross(glm::vec3(p.p1), glm::vec3(p.p2)));
  const glm::vec2 du = uv[1] - uv[0], dv = uv[2] - uv[0];
  const float area_uv = std::abs(du.x * dv.y - du.y * dv.x);
  const auto slot = std::uint32_t(records->size() / SURFACE_UV_TEXELS);
  p.p1.w = glm::uintBitsToFloat(slot + 1u);
  const auto word = [](float f) { return glm::floatBitsToUint(f); };
  records->emplace_back(word(uv[0].x), word(uv[0].y), word(uv[1].x), word(uv[1].y));
  records->emplace_back(word(uv[2].x), word(uv[2].y), word(std::sqrt(area_uv / area_m2)), 0u);
}

// Quads are split along their first diagonal; vertex order keeps the winding,
// so cross(p1, p2) is the outward normal. `uv`: the corners' texture
// coordinates, for a textured object.
void add_quad(std::vector<gpu::Primitive> &out, const std::array<glm::vec3, 4> &q,
              std::uint32_t bits, UvRecords *records = nullptr,
              const std::array<glm::vec2, 4> &uv = {}) {
  std::size_t before = out.size();
  add_triangle(out, q[0], q[1], q[2], bits);
  add_uv_record(out, before, records, {uv[0], uv[1], uv[2]});
  before = out.size();
  add_triangle(out, q[0], q[2], q[3], bits);
  add_uv_record(out, before, records, {uv[0], uv[2], uv[3]});
}

// The texture coordinates of a corner c of the unit cube (-0.5 .. 0.5) on
// the face whose outward normal is n (Material::albedo_texture): u along the
// face's right as seen from outside, v down it.
glm::vec2 box_face_uv(const glm::vec3 &c, const glm::vec3 &n) {
  glm::vec3 right(1.0f, 0.0f, 0.0f), down(0.0f, 0.0f, 1.0f); // the top face: as a plane
  if (n.y < -0.5f) {
    down = glm::vec3(0.0f, 0.0f, -1.0f); // the bottom face, seen from below
  } else if (n.y < 0.5f) {
    down = glm::vec3(0.0f, -1.0f, 0.0f);
    right = glm::cross(-n, glm::vec3(0.0f, 1.0f, 0.0f));
  }
  return {glm::dot(c, right) + 0.5f, glm::dot(c, down) + 0.5f};
}

// `origin`: the compiled frame's zero (CompiledScene::origin), taken off the
// translation before the vertices are formed, where float has the most bits.
// `records`: where a textured object's triangles put their texture
// coordinates, null for an untextured one.
void add_object(std::vector<gpu::Primitive> &out, const Object &o, const glm::vec3 &origin,
                UvRecords *records) {
  const glm::vec3 center = o.center - origin;
  switch (o.type) {
  case ShapeType::plane: {
    // XZ plane, normal +Y before rotation; size is (x, unused, z).
    const Transform xf(center, o.rotation_deg, glm::vec3(o.size.x, 1.0f, o.size.z));
    add_quad(out,
             {xf({-0.5f, 0.0f, 0.5f}), xf({0.5f, 0.0f, 0.5f}), xf({0.5f, 0.0f, -0.5f}),
              xf({-0.5f, 0.0f, -0.5f})},
             primitive_bits(o, PRIM_TRIANGLE), records, {{{0, 1}, {1, 1}, {1, 0}, {0, 0}}});
    break;
  }
  case ShapeType::box: {
    // Corner i has x, y, z = bits 2, 1, 0 of i; faces as add_object() lists them.
    const Transform xf(center, o.rotation_deg, o.size);
    std::array<glm::vec3, 8> unit, v;
    for (int i = 0; i < 8; ++i) {
      unit[i] = glm::vec3((i >> 2) & 1, (i >> 1) & 1, i & 1) - glm::vec3(0.5f);
      v[i] = xf(unit[i]);
    }
    constexpr int kFaces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                  {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    const std::uint32_t bits = primitive_bits(o, PRIM_TRIANGLE);
    for (const auto &f : kFaces) {
      const glm::vec3 normal =
          0.5f * (unit[f[0]] + unit[f[1]] + unit[f[2]] + unit[f[3]]); // the face's centre x 2
      std::array<glm::vec2, 4> uv;
      for (int k = 0; k < 4; ++k)
        uv[k] = box_face_uv(unit[f[k]], normal);
      add_quad(out, {v[f[0]], v[f[1]], v[f[2]], v[f[3]]}, bits, records, uv);
    }
    break;
  }
  case ShapeType::sphere:
    out.push_back(
        gpu::Primitive{gpu::vec4(center, glm::uintBitsToFloat(primitive_bits(o, PRIM_SPHERE))),
                       gpu::vec4(o.radius, 0.0f, 0.0f, 0.0f), gpu::vec4(0.0f)});
    break;
  case ShapeType::mesh: {
    if (!o.mesh)
      throw std::invalid_argument("object " + o.name + ": mesh not loaded");
    const Transform xf(center, o.rotation_deg, glm::vec3(o.scale));
    const TriangleMesh &m = *o.mesh;
    std::vector<glm::vec3> world;
    world.reserve(m.positions.size());
    for (const glm::vec3 &p : m.positions)
      world.push_back(xf(p));
    const std::uint32_t bits = primitive_bits(o, PRIM_TRIANGLE);
    out.reserve(out.size() + m.triangles.size());
    for (const glm::uvec3 &t : m.triangles) {
      if (t.x >= world.size() || t.y >= world.size() || t.z >= world.size())
        throw std::invalid_argument("object " + o.name + ": triangle index out of range");
      add_triangle(out, world[t.x], world[t.y], world[t.z], bits);
    }
    break;
  }
  }
}

// Where a compiled texture lies in CompiledScene::surfaces.
struct TexturePlace {
  std::uint32_t base = 0;
  std::uint32_t width = 0; // 0: none
  std::uint32_t height = 0;
};

// One level of a texture, linear RGB.
struct TextureLevel {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> rgb;
};

TextureLevel level_zero(const Image &image) {
  TextureLevel level{image.width, image.height, std::vector<glm::vec3>(image.pixel_count())};
  for (std::size_t i = 0; i < level.rgb.size(); ++i) {
    const float *px = &image.data[i * std::size_t(image.channels)];
    level.rgb[i] = image.channels >= 3 ? glm::vec3(px[0], px[1], px[2]) : glm::vec3(px[0]);
  }
  return level;
}

// The next level, half the size rounded down (at least 1): each pixel the
// mean of the 2 x 2 below it (of the 2 along a side 1 pixel long). An odd
// side's last row or column is left out, as GPUs' own mip levels do: it
// shifts that level's picture by at most half a texel.
TextureLevel half_level(const TextureLevel &src) {
  TextureLevel out{std::max(src.width / 2, 1), std::max(src.height / 2, 1), {}};
  out.rgb.resize(std::size_t(out.width) * std::size_t(out.height));
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      glm::vec3 sum(0.0f);
      int n = 0;
      for (int sy = 2 * y; sy < std::min(2 * y + 2, src.height); ++sy)
        for (int sx = 2 * x; sx < std::min(2 * x + 2, src.width); ++sx, ++n)
          sum += src.rgb[std::size_t(sy) * std::size_t(src.width) + std::size_t(sx)];
      out.rgb[std::size_t(y) * std::size_t(out.width) + std::size_t(x)] = sum / float(n);
    }
  return out;
}

// Appends `image` and its mip levels to `surfaces` (layout.h).
TexturePlace add_texture(std::vector<glm::uvec4> &surfaces, const Image &image) {
  if (image.width <= 0 || image.height <= 0)
    throw std::invalid_argument("an albedo texture is empty");
  const TexturePlace place{std::uint32_t(surfaces.size()), std::uint32_t(image.width),
                           std::uint32_t(image.height)};
  TextureLevel level = level_zero(image);
  for (;;) {
    const std::size_t first = surfaces.size();
    surfaces.resize(first + (level.rgb.size() + 1) / 2, glm::uvec4(0u));
    for (std::size_t i = 0; i < level.rgb.size(); ++i) {
      const glm::vec3 &c = level.rgb[i];
      glm::uvec4 &word = surfaces[first + i / 2];
      const glm::uint rg = glm::packHalf2x16(glm::vec2(c.r, c.g));
      const glm::uint b = glm::packHalf2x16(glm::vec2(c.b, 0.0f));
      (i % 2 == 0 ? word.x : word.z) = rg;
      (i % 2 == 0 ? word.y : word.w) = b;
    }
    if (level.width == 1 && level.height == 1)
      break;
    level = half_level(level);
  }
  return place;
}

gpu::Material compile_material(const Material &m, const TexturePlace &texture) {
  std::uint32_t type = MAT_DIFFUSE;
  switch (m.type) {
  case MaterialType::diffuse:
    type = MAT_DIFFUSE;
    break;
  case MaterialType::mirror:
    type = MAT_MIRROR;
    break;
  case MaterialType::glass:
    type = MAT_GLASS;
    break;
  case MaterialType::emission:
    type = MAT_EMISSION;
    break;
  }
  return gpu::Material{gpu::vec4(m.color, glm::uintBitsToFloat(texture.base)),
                       gpu::vec4(m.ior, glm::uintBitsToFloat(texture.width),
                                 glm::uintBitsToFloat(texture.height), glm::uintBitsToFloat(type))};
}

gpu::Light compile_light(const Light &l, const glm::vec3 &origin) {
  gpu::Light g{};
  switch (l.type) {
  case LightType::point:
    g.position = gpu::vec4(l.position - origin, glm::uintBitsToFloat(LIGHT_POINT));
    g.emission = gpu::vec4(l.color * (l.power_W / (4.0f * kPi)), 0.0f);
    break;
  case LightType::area: {
    // add_light() orients the rectangle with look_at_matrix(pos, pos + n, a):
    // local x = normalize(n x a), local y = z x x with z = -n, i.e. u x n.
    const glm::vec3 n = glm::normalize(l.normal);
    const glm::vec3 a = std::abs(n.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, -1);
    const glm::vec3 u = glm::normalize(glm::cross(n, a));
    const glm::vec3 v = glm::cross(u, n);
    const float area = l.size.x * l.size.y;
    g.position = gpu::vec4(l.position - origin, glm::uintBitsToFloat(LIGHT_AREA));
    g.emission = gpu::vec4(l.color * (l.power_W / (4.0f * area)), 0.0f);
    g.axis_u = gpu::vec4(u * l.size.x, area);
    g.axis_v = gpu::vec4(v * l.size.y, 0.0f);
    g.normal = gpu::vec4(n, 0.0f);
    break;
  }
  case LightType::sun:
    g.position = gpu::vec4(0.0f, 0.0f, 0.0f, glm::uintBitsToFloat(LIGHT_SUN));
    g.emission = gpu::vec4(l.color * l.irradiance_W_m2, 0.0f);
    g.normal = gpu::vec4(glm::normalize(l.direction), 0.0f);
    break;
  }
  return g;
}

// The bounds of primitives [first, end) of `prims`, false when empty.
bool primitive_bounds(const std::vector<gpu::Primitive> &prims, std::size_t first,
                      ObjectBounds &b) {
  if (first == prims.size())
    return false;
  b.lo = glm::vec3(std::numeric_limits<float>::infinity());
  b.hi = -b.lo;
  for (std::size_t i = first; i < prims.size(); ++i) {
    const gpu::Primitive &p = prims[i];
    const glm::vec3 p0(p.p0);
    if ((glm::floatBitsToUint(p.p0.w) >> 24) == PRIM_SPHERE) {
      b.lo = glm::min(b.lo, p0 - glm::vec3(p.p1.x));
      b.hi = glm::max(b.hi, p0 + glm::vec3(p.p1.x));
      continue;
    }
    for (const glm::vec3 &v : {p0, p0 + glm::vec3(p.p1), p0 + glm::vec3(p.p2)}) {
      b.lo = glm::min(b.lo, v);
      b.hi = glm::max(b.hi, v);
    }
  }
  return true;
}

// The extent of primitives [first, end) of `prims` along the columns of b.axes.
void axis_bounds(const std::vector<gpu::Primitive> &prims, std::size_t first, ObjectBounds &b) {
  b.axis_lo = glm::vec3(std::numeric_limits<float>::infinity());
  b.axis_hi = -b.axis_lo;
  const glm::mat3 to_axes = glm::transpose(b.axes);
  for (std::size_t i = first; i < prims.size(); ++i) {
    const gpu::Primitive &p = prims[i];
    const glm::vec3 p0(p.p0);
    if ((glm::floatBitsToUint(p.p0.w) >> 24) == PRIM_SPHERE) {
      b.axis_lo = glm::min(b.axis_lo, to_axes * p0 - glm::vec3(p.p1.x));
      b.axis_hi = glm::max(b.axis_hi, to_axes * p0 + glm::vec3(p.p1.x));
      continue;
    }
    for (const glm::vec3 &v : {p0, p0 + glm::vec3(p.p1), p0 + glm::vec3(p.p2)}) {
      b.axis_lo = glm::min(b.axis_lo, to_axes * v);
      b.axis_hi = glm::max(b.axis_hi, to_axes * v);
    }
  }
}

std::vector<glm::vec4> compile_plate(const Scene &scene) {
  const Image &img = *scene.plate;
  if (img.width != scene.render.width || img.height != scene.render.height ||
      (img.channels != 1 && img.channels != 3))
    throw std::invalid_argument(
        scene.source.string() + ": plate is " + std::to_string(img.width) + "x" +
        std::to_string(img.height) + "x" + std::to_string(img.channels) + ", the render " +
        std::to_string(scene.render.width) + "x" + std::to_string(scene.render.height) + " rgb");
  std::vector<glm::vec4> rgb(img.pixel_count());
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    const float *px = &img.data[i * img.channels];
    rgb[i] = img.channels == 3 ? glm::vec4(px[0], px[1], px[2], 0.0f)
                               : glm::vec4(px[0], px[0], px[0], 0.0f);
  }
  return rgb;
}

} // namespace

CompiledScene compile_scene(const Scene &scene) {
  CompiledScene out;
  // Far from the world origin a float coordinate of the scene has lost most
  // of its bits, and the kernel's ray offsets (CAMHEAD_RAY_EPSILON) grow with
  // it: at 1 km they lift shadow rays 10 cm off the surface.
  constexpr float kOriginGridM = 64.0f;
  out.origin = glm::round(scene.camera.position / kOriginGridM) * kOriginGridM;
  const auto textured = [&](const Object &o) {
    return std::size_t(o.material) < scene.materials.size() &&
           scene.materials[std::size_t(o.material)].type == MaterialType::diffuse &&
           scene.materials[std::size_t(o.material)].albedo_texture.image &&
           (o.type == ShapeType::plane || o.type == ShapeType::box);
  };
  std::vector<gpu::Primitive> prims;
  for (const Object &o : scene.objects) {
    const std::size_t first = prims.size();
    add_object(prims, o, out.origin, textured(o) ? &out.surfaces : nullptr);
    ObjectBounds bounds;
    if (!primitive_bounds(prims, first, bounds))
      continue;
    // An index past the materials is the scene loader's error to report; the
    // kernel reads such primitives as diffuse.
    const MaterialType type = std::size_t(o.material) < scene.materials.size()
                                  ? scene.materials[std::size_t(o.material)].type
                                  : MaterialType::diffuse;
    bounds.real = o.real;
    bounds.specular = type == MaterialType::mirror || type == MaterialType::glass;
    bounds.shaded = type == MaterialType::diffuse;
    bounds.axes = euler_xyz(o.rotation_deg);
    axis_bounds(prims, first, bounds);
    if (o.type == ShapeType::sphere) {
      bounds.sphere = true;
      bounds.centre = glm::vec3(prims.back().p0);
      bounds.radius = prims.back().p1.x;
    }
    out.objects.push_back(bounds);
  }
  Bvh bvh = build_bvh(std::move(prims));
  out.primitives = std::move(bvh.primitives);
  out.nodes = std::move(bvh.nodes);
  // The textures after the texture coordinates, each once however many
  // materials share it.
  std::vector<std::pair<const Image *, TexturePlace>> textures;
  for (const Material &m : scene.materials) {
    TexturePlace place;
    if (const Image *image = m.albedo_texture.image.get();
        m.type == MaterialType::diffuse && image) {
      const auto known = std::find_if(textures.begin(), textures.end(),
                                      [&](const auto &t) { return t.first == image; });
      place = known != textures.end()
                  ? known->second
                  : textures.emplace_back(image, add_texture(out.surfaces, *image)).second;
    }
    out.materials.push_back(compile_material(m, place));
  }
  for (const Light &l : scene.lights)
    out.lights.push_back(compile_light(l, out.origin));
  if (scene.plate)
    out.plate = compile_plate(scene);
  out.width = scene.render.width;
  out.height = scene.render.height;
  return out;
}

FrameCamera scene_camera(const Scene &scene) {
  const CameraDesc &cam = scene.camera;
  FrameCamera camera;
  camera.position = cam.position;
  camera.look_at = cam.look_at;
  camera.up = cam.up;
  camera.focus_distance_m = cam.focus_distance_m;
  camera.f_number = cam.f_number;
  camera.focal_length_mm = cam.focal_length_mm;
  camera.projection_focal_length_mm = cam.focal_length_mm;
  camera.sensor_width_mm = cam.sensor_width_mm;
  return camera;
}

gpu::FrameParams make_frame_params(const Scene &scene, int samples) {
  return make_frame_params(scene, scene_camera(scene), samples);
}

gpu::FrameParams make_frame_params(const Scene &scene, const FrameCamera &cam, int samples) {
  const RenderSettings &r = scene.render;
  // look_at_matrix(): camera -Z toward the target, x = up x z, y = z x x.
  const glm::vec3 forward = glm::normalize(cam.look_at - cam.position);
  const glm::vec3 right = glm::normalize(glm::cross(forward, cam.up));
  const glm::vec3 up = glm::cross(right, forward);

  const float f_m = cam.focal_length_mm / 1000.0f;
  const float aperture_radius = cam.f_number > 0.0f ? f_m / (2.0f * cam.f_number) : 0.0f;
  // A pinhole ignores the focal depth; a positive stand-in keeps any code
  // that forms the focal point (I = O + d d_f / cos) off the degenerate I = O.
  // Focus at infinity (lens_control reports +inf) and beyond the scene
  // loader's limit is put at that limit: an infinite focal point makes every
  // lens ray NaN (a blank frame), and at 1e6 m the lens rays are parallel to
  // the pinhole ray to within a micro-radian.
  constexpr float kFarthestFocusM = 1e6f;
  const float focus = cam.focus_distance_m > 0.0f ? std::min(cam.focus_distance_m, kFarthestFocusM)
                                                  : 1.0f; // also NaN
  // Cycles' projection: magnification set by the focal length alone; with
  // breathing data, by the projection focal length.
  const float projection_mm =
      cam.projection_focal_length_mm > 0.0f ? cam.projection_focal_length_mm : cam.focal_length_mm;
  const float focal_px = projection_mm * float(r.width) / cam.sensor_width_mm;
  const glm::vec3 pupil = cam.position + cam.entrance_pupil_offset_m * forward;

  const auto spp = std::uint32_t(samples > 0 ? samples : r.samples);
  gpu::FrameParams fp{};
  fp.cam_position = gpu::vec4(pupil, 0.0f);
  fp.cam_right = gpu::vec4(right, 0.0f);
  fp.cam_up = gpu::vec4(up, 0.0f);
  fp.cam_forward = gpu::vec4(forward, 0.0f);
  fp.lens = gpu::vec4(aperture_radius, focus, focal_px, r.pixel_filter_width_px);
  fp.world_color = gpu::vec4(r.world_color, 0.0f);
  fp.image = gpu::uvec4(std::uint32_t(r.width), std::uint32_t(r.height), scene.plate ? 1u : 0u,
                        std::uint32_t(scene.lights.size()));
  fp.sampling = gpu::uvec4(0u, spp, spp, r.seed);
  fp.tracing = gpu::uvec4(std::uint32_t(r.max_bounces), 0u, 0u, 0u);
  if (const LensModel &m = cam.lens_model; !m.ideal()) {
    fp.tracing.w |= TRACING_LENS_MODEL;
    fp.projection = gpu::vec4(m.principal_point.x * float(r.width),
                              m.principal_point.y * float(r.height), m.fy_over_fx, m.k3);
    fp.distortion = gpu::vec4(m.k1, m.k2, m.p1, m.p2);
  }
  return fp;
}

} // namespace camhead::renderer
