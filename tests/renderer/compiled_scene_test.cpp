// compile_scene must place geometry and lights exactly as reference/
// blender_scene.py does in Blender, so expected values here come from an
// independent construction (glm::rotate composition, a re-implementation of
// look_at_matrix) or from hand-worked cases, never from the code under test.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/compiled_scene.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

constexpr float kPi = 3.14159265358979323846f;

std::uint32_t bits(float w) {
  return glm::floatBitsToUint(w);
}

std::array<glm::vec3, 3> vertices(const gpu::Primitive &p) {
  const glm::vec3 v0(p.p0);
  return {v0, v0 + glm::vec3(p.p1), v0 + glm::vec3(p.p2)};
}

glm::vec3 normal(const gpu::Primitive &p) {
  return glm::cross(glm::vec3(p.p1), glm::vec3(p.p2));
}

void expect_near(const glm::vec3 &got, const glm::vec3 &want, float tol = 1e-5f) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

Scene scene_with(std::vector<Object> objects) {
  Scene s;
  s.materials = {{"grey", MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}},
                 {"chrome", MaterialType::mirror, glm::vec3(0.9f, 0.8f, 0.7f), 1.5f, {}},
                 {"glass", MaterialType::glass, glm::vec3(1.0f), 1.33f, {}},
                 {"lamp", MaterialType::emission, glm::vec3(2.0f, 1.0f, 0.5f), 1.5f, {}}};
  s.objects = std::move(objects);
  return s;
}

Object make(ShapeType type, glm::vec3 center, glm::vec3 rotation_deg = glm::vec3(0)) {
  Object o;
  o.name = "o";
  o.type = type;
  o.center = center;
  o.rotation_deg = rotation_deg;
  return o;
}

// Blender's Euler 'XYZ' as trs() applies it: X first, then Y, then Z.
glm::mat4 trs(glm::vec3 center, glm::vec3 deg, glm::vec3 scale) {
  glm::mat4 m = glm::translate(glm::mat4(1), center);
  m = glm::rotate(m, glm::radians(deg.z), glm::vec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(deg.y), glm::vec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(deg.x), glm::vec3(1, 0, 0));
  return glm::scale(m, scale);
}

TEST(CompiledScene, RotatedBoxCornersFollowXyzEuler) {
  Object box = make(ShapeType::box, {1, 2, -3}, {20, 30, 40});
  box.size = {0.3f, 0.5f, 0.7f};
  const CompiledScene c = compile_scene(scene_with({box}));
  ASSERT_EQ(c.primitives.size(), 12u);

  const glm::mat4 m = trs(box.center, box.rotation_deg, box.size);
  std::array<glm::vec3, 8> corners;
  for (int i = 0; i < 8; ++i)
    corners[i] = glm::vec3(m * glm::vec4(glm::vec3(i >> 2 & 1, i >> 1 & 1, i & 1) - 0.5f, 1));
  std::array<int, 8> used{};
  float area = 0;
  for (const gpu::Primitive &p : c.primitives) {
    EXPECT_EQ(bits(p.p0.w) >> 24, PRIM_TRIANGLE);
    glm::vec3 centroid(0);
    for (const glm::vec3 &v : vertices(p)) {
      const auto it = std::min_element(corners.begin(), corners.end(), [&](auto a, auto b) {
        return glm::distance(a, v) < glm::distance(b, v);
      });
      EXPECT_LT(glm::distance(*it, v), 1e-5f);
      ++used[it - corners.begin()];
      centroid += v / 3.0f;
    }
    EXPECT_GT(glm::dot(normal(p), centroid - box.center), 0) << "normal must face outwards";
    area += 0.5f * glm::length(normal(p));
  }
  for (int u : used)
    EXPECT_GE(u, 3); // every corner touches three faces
  EXPECT_NEAR(area, 2 * (0.3f * 0.5f + 0.5f * 0.7f + 0.7f * 0.3f), 1e-5f);
}

// A worked case that tells XYZ from ZYX: Rx(90) then Rz(90) sends the local
// x extent to world y, y to z and z to x.
TEST(CompiledScene, EulerOrderIsXThenYThenZ) {
  Object box = make(ShapeType::box, {0, 0, 0}, {90, 0, 90});
  box.size = {1, 2, 3};
  const CompiledScene c = compile_scene(scene_with({box}));
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const gpu::Primitive &p : c.primitives)
    for (const glm::vec3 &v : vertices(p))
      lo = glm::min(lo, v), hi = glm::max(hi, v);
  expect_near(hi - lo, {3, 1, 2});
}

TEST(CompiledScene, PlaneTrianglesCoverExactlyItsRectangle) {
  Object plane = make(ShapeType::plane, {1, 0.5f, -3});
  plane.size = {4, 0, 2};
  const CompiledScene c = compile_scene(scene_with({plane}));
  ASSERT_EQ(c.primitives.size(), 2u);
  float area = 0;
  for (const gpu::Primitive &p : c.primitives) {
    for (const glm::vec3 &v : vertices(p)) {
      EXPECT_FLOAT_EQ(v.y, 0.5f);
      EXPECT_TRUE(v.x == -1 || v.x == 3) << v.x;
      EXPECT_TRUE(v.z == -4 || v.z == -2) << v.z;
    }
    EXPECT_GT(normal(p).y, 0) << "normal +Y before rotation";
    area += 0.5f * glm::length(normal(p));
  }
  EXPECT_FLOAT_EQ(area, 8);
  // Every point of the rectangle lies in exactly one triangle (the shared
  // diagonal aside, which random points miss).
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> ux(-1, 3), uz(-4, -2);
  for (int i = 0; i < 1000; ++i) {
    const glm::vec3 q(ux(rng), 0.5f, uz(rng));
    int inside = 0;
    for (const gpu::Primitive &p : c.primitives) {
      const auto v = vertices(p);
      const glm::vec3 n = normal(p);
      bool in = true;
      for (int k = 0; k < 3; ++k)
        in = in && glm::dot(glm::cross(v[(k + 1) % 3] - v[k], q - v[k]), n) >= 0;
      inside += in;
    }
    EXPECT_EQ(inside, 1) << q.x << " " << q.z;
  }
  // Rx(90) turns the normal from +Y to +Z.
  plane.rotation_deg = {90, 0, 0};
  for (const gpu::Primitive &p : compile_scene(scene_with({plane})).primitives)
    expect_near(glm::normalize(normal(p)), {0, 0, 1});
}

TEST(CompiledScene, SpheresAreAnalyticAndBitsPacked) {
  Object ball = make(ShapeType::sphere, {-0.3f, 0.2f, -1.2f}, {10, 20, 30});
  ball.radius = 0.2f;
  ball.material = 2;
  ball.real = true;
  Object box = make(ShapeType::box, {0, 0, 0});
  box.material = 1;
  const CompiledScene c = compile_scene(scene_with({ball, box}));
  ASSERT_EQ(c.primitives.size(), 13u);
  int spheres = 0;
  for (const gpu::Primitive &p : c.primitives) {
    const std::uint32_t b = bits(p.p0.w);
    if (b >> 24 == PRIM_SPHERE) {
      ++spheres;
      EXPECT_EQ(b, 2u | PRIM_REAL_BIT | PRIM_SPHERE << 24);
      expect_near(glm::vec3(p.p0), ball.center, 0);
      EXPECT_EQ(p.p1.x, 0.2f);
    } else {
      EXPECT_EQ(b, 1u);
      EXPECT_EQ(b & PRIM_MATERIAL_MASK, 1u);
    }
  }
  EXPECT_EQ(spheres, 1);
}

TEST(CompiledScene, MeshIsScaledRotatedTranslatedAndDegeneratesDropped) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {10, 0, 0}, {0, 1e-3f, 0}};
  // The 2nd and 3rd have no area (the 3rd keeps a sliver of rounding once
  // rotated); the 4th is thin but real.
  mesh->triangles = {{0, 1, 2}, {0, 1, 1}, {0, 1, 3}, {0, 4, 5}};
  Object o = make(ShapeType::mesh, {1, 0, 0}, {0, 90, 0});
  o.mesh = mesh;
  o.scale = 2;
  o.material = 3;
  const CompiledScene c = compile_scene(scene_with({o}));
  ASSERT_EQ(c.primitives.size(), 2u);
  const bool first_is_big = glm::length(normal(c.primitives[0])) > 1;
  const auto v = vertices(c.primitives[first_is_big ? 0 : 1]);
  // Ry(90) sends x to -z; scale 2, then +1 in x.
  expect_near(v[0], {1, 0, 0});
  expect_near(v[1], {1, 0, -2});
  expect_near(v[2], {1, 2, 0});
  EXPECT_EQ(bits(c.primitives[0].p0.w), 3u);
}

TEST(CompiledScene, MaterialsCarryColourIorAndType) {
  const CompiledScene c = compile_scene(scene_with({}));
  ASSERT_EQ(c.materials.size(), 4u);
  const std::uint32_t types[] = {MAT_DIFFUSE, MAT_MIRROR, MAT_GLASS, MAT_EMISSION};
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(bits(c.materials[i].params.w), types[i]);
  expect_near(glm::vec3(c.materials[1].color), {0.9f, 0.8f, 0.7f}, 0);
  EXPECT_EQ(c.materials[2].params.x, 1.33f);
  expect_near(glm::vec3(c.materials[3].color), {2, 1, 0.5f}, 0);
}

// look_at_matrix(pos, pos + n, a) from blender_scene.py: the light's local
// x and y, along which Blender lays size[0] and size[1].
std::array<glm::vec3, 2> blender_area_axes(glm::vec3 n) {
  n = glm::normalize(n);
  const glm::vec3 a = std::abs(n.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, -1);
  const glm::vec3 z = -n;
  const glm::vec3 x = glm::normalize(glm::cross(a, z));
  return {x, glm::cross(z, x)};
}

gpu::Light compile_one(const Light &l) {
  Scene s = scene_with({});
  s.lights = {l};
  return compile_scene(s).lights.at(0);
}

Light area_light(glm::vec3 normal_dir, glm::vec2 size, float power = 100) {
  Light l;
  l.type = LightType::area;
  l.position = {0, 3, -2};
  l.normal = normal_dir;
  l.size = size;
  l.power_W = power;
  l.color = {1, 0.5f, 0.25f};
  return l;
}

TEST(CompiledScene, AreaLightAxesFollowBlendersOrientation) {
  // Wall light facing +Z: size[0] along n x Y = -X, size[1] up.
  gpu::Light g = compile_one(area_light({0, 0, 1}, {2, 0.5f}));
  EXPECT_EQ(bits(g.position.w), LIGHT_AREA);
  expect_near(glm::vec3(g.position), {0, 3, -2}, 0);
  expect_near(glm::vec3(g.axis_u), {-2, 0, 0});
  expect_near(glm::vec3(g.axis_v), {0, 0.5f, 0});
  expect_near(glm::vec3(g.normal), {0, 0, 1});
  EXPECT_FLOAT_EQ(g.axis_u.w, 1.0f);
  expect_near(glm::vec3(g.emission), glm::vec3(1, 0.5f, 0.25f) * 100.0f / 4.0f);

  // Ceiling light facing down: size[0] along X, size[1] along -Z.
  g = compile_one(area_light({0, -1, 0}, {1, 3}));
  expect_near(glm::vec3(g.axis_u), {1, 0, 0});
  expect_near(glm::vec3(g.axis_v), {0, 0, -3});
  EXPECT_FLOAT_EQ(g.axis_u.w, 3.0f);
  expect_near(glm::vec3(g.emission), glm::vec3(1, 0.5f, 0.25f) * 100.0f / 12.0f);

  // 5.7 degrees off vertical still takes -Z as the reference; 10 degrees not.
  std::vector<glm::vec3> normals = {{0.1f, -1, 0}, {0, 1, 0.1f}, {0.18f, -1, 0}, {1, 0, 0}};
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int i = 0; i < 50; ++i)
    normals.emplace_back(u(rng), u(rng), u(rng));
  for (const glm::vec3 &n : normals) {
    if (glm::length(n) < 0.1f)
      continue;
    g = compile_one(area_light(n, {0.7f, 1.3f}));
    const auto [x, y] = blender_area_axes(n);
    expect_near(glm::vec3(g.axis_u), 0.7f * x);
    expect_near(glm::vec3(g.axis_v), 1.3f * y);
    expect_near(glm::vec3(g.normal), glm::normalize(n));
    EXPECT_NEAR(glm::dot(glm::vec3(g.axis_u), glm::vec3(g.axis_v)), 0, 1e-6f);
  }
}

TEST(CompiledScene, PointAndSunLights) {
  Light point;
  point.type = LightType::point;
  point.position = {0.8f, 2.5f, 0.5f};
  point.power_W = 200;
  gpu::Light g = compile_one(point);
  EXPECT_EQ(bits(g.position.w), LIGHT_POINT);
  expect_near(glm::vec3(g.position), point.position, 0);
  expect_near(glm::vec3(g.emission), glm::vec3(200 / (4 * kPi)));

  Light sun;
  sun.type = LightType::sun;
  sun.direction = {-0.3f, -1, -0.2f};
  sun.irradiance_W_m2 = 3;
  sun.color = {1, 0.9f, 0.8f};
  g = compile_one(sun);
  EXPECT_EQ(bits(g.position.w), LIGHT_SUN);
  expect_near(glm::vec3(g.emission), {3, 2.7f, 2.4f});
  expect_near(glm::vec3(g.normal), glm::normalize(sun.direction));
}

// boxes.json, by hand (the loader is tested on its own).
Scene boxes_scene() {
  Object ground = make(ShapeType::plane, {0, 0, -5});
  ground.size = {20, 0, 20};
  ground.real = true;
  Scene s = scene_with({ground});
  const glm::vec3 centers[] = {
      {-0.12f, 0.225f, -0.54f}, {0.15f, 0.15f, -1.65f}, {-0.4f, 0.3f, -4.3f}};
  const glm::vec3 sizes[] = {{0.08f, 0.45f, 0.08f}, glm::vec3(0.3f), glm::vec3(0.6f)};
  for (int i = 0; i < 3; ++i) {
    Object b = make(ShapeType::box, centers[i]);
    b.size = sizes[i];
    b.real = true;
    s.objects.push_back(b);
  }
  Light key;
  key.position = {0.8f, 2.5f, 0.5f};
  key.power_W = 200;
  s.lights = {key};
  s.render.width = 720;
  s.render.height = 576;
  s.render.samples = 64;
  s.camera = {{0, 0.5f, 0}, {0, 0.5f, -1}, {0, 1, 0}, 35, 36, 1.8f, 1.5f};
  return s;
}

TEST(CompiledScene, FrameParamsForBoxes) {
  Scene s = boxes_scene();
  const CompiledScene c = compile_scene(s);
  EXPECT_EQ(c.primitives.size(), 2u + 3 * 12);
  EXPECT_EQ(c.width, 720);
  EXPECT_EQ(c.height, 576);
  EXPECT_TRUE(c.plate.empty());

  const gpu::FrameParams f = make_frame_params(s);
  expect_near(glm::vec3(f.cam_position), {0, 0.5f, 0}, 0);
  expect_near(glm::vec3(f.cam_right), {1, 0, 0});
  expect_near(glm::vec3(f.cam_up), {0, 1, 0});
  expect_near(glm::vec3(f.cam_forward), {0, 0, -1});
  EXPECT_FLOAT_EQ(f.lens.x, 0.035f / (2 * 1.8f));
  EXPECT_FLOAT_EQ(f.lens.y, 1.5f);
  EXPECT_FLOAT_EQ(f.lens.z, 700.0f); // 35 mm * 720 px / 36 mm
  EXPECT_EQ(f.lens.w, 1.0f);         // box filter width in pixels
  EXPECT_EQ(f.image, glm::uvec4(720, 576, 0, 1));
  EXPECT_EQ(f.sampling, glm::uvec4(0, 64, 64, 0));
  EXPECT_EQ(f.tracing, glm::uvec4(0, 0, 0, 0));

  // An explicit sample count overrides the scene's.
  s.render.seed = 7;
  const gpu::FrameParams g = make_frame_params(s, 16);
  EXPECT_EQ(g.sampling, glm::uvec4(0, 16, 16, 7));
  EXPECT_EQ(g.lens, f.lens);
}

TEST(CompiledScene, CameraFrameIsOrthonormalAndRightHanded) {
  Scene s = boxes_scene();
  s.camera.position = {1, 2, 3};
  s.camera.look_at = {-0.5f, 0.2f, -1};
  s.camera.up = {0.1f, 1, 0};
  s.camera.f_number = 0; // pinhole
  const gpu::FrameParams f = make_frame_params(s);
  const glm::vec3 r(f.cam_right), u(f.cam_up), fw(f.cam_forward);
  for (const glm::vec3 &v : {r, u, fw})
    EXPECT_NEAR(glm::length(v), 1, 1e-6f);
  EXPECT_NEAR(glm::dot(r, u), 0, 1e-6f);
  EXPECT_NEAR(glm::dot(r, fw), 0, 1e-6f);
  EXPECT_NEAR(glm::dot(u, fw), 0, 1e-6f);
  expect_near(glm::cross(r, u), -fw); // camera looks down its -Z
  expect_near(fw, glm::normalize(s.camera.look_at - s.camera.position));
  EXPECT_NEAR(glm::dot(r, s.camera.up), 0, 1e-6f); // no roll about the view axis
  EXPECT_GT(glm::dot(u, s.camera.up), 0);
  EXPECT_EQ(f.lens.x, 0.0f);
  EXPECT_GT(f.lens.y, 0.0f); // any positive depth; the pinhole ray ignores it
}

TEST(CompiledScene, PlateIsCopiedAsRgb) {
  Scene s = boxes_scene();
  s.render.width = 2;
  s.render.height = 1;
  Image plate(2, 1, 3);
  plate.data = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
  s.plate = plate;
  const CompiledScene c = compile_scene(s);
  ASSERT_EQ(c.plate.size(), 2u);
  EXPECT_EQ(c.plate[1], glm::vec4(0.4f, 0.5f, 0.6f, 0));
  EXPECT_EQ(make_frame_params(s).image.z, 1u);
}

} // namespace
} // namespace camhead::renderer
