// The scene flattened into the buffers that the tracers read (layout.h):
// primitives in BVH order, BVH nodes, materials, lights, textures and the
// plate.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "camhead/renderer/frame_camera.h"
#include "camhead/renderer/gpu_layout.h"
#include "camhead/renderer/scene.h"

namespace camhead::renderer {

// The bounds of one scene object's primitives, in the compiled frame, and
// what the influence region (influence_region.h) needs to know of it.
struct ObjectBounds {
  glm::vec3 lo{0.0f};
  glm::vec3 hi{0.0f};
  bool real = false;     // part of the real proxy
  bool specular = false; // mirror or glass: shows what lies elsewhere
  bool shaded = false;   // diffuse: receives light, and so shadows
  // Its extent along its own axes (the columns of `axes`, orthonormal: the
  // object's rotation): an oriented box, which a rotated box or plane fills
  // exactly where lo/hi, aligned with the world, does not.
  glm::mat3 axes{1.0f};
  glm::vec3 axis_lo{0.0f};
  glm::vec3 axis_hi{0.0f};
  // A sphere's own shape, tighter than its box.
  bool sphere = false;
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
};

struct CompiledScene {
  std::vector<gpu::Primitive> primitives; // ordered as the BVH leaves use them
  std::vector<gpu::BvhNode> nodes;        // nodes[0] is the root
  std::vector<gpu::Material> materials;
  std::vector<gpu::Light> lights;
  // Textured triangles' texture coordinates, then the albedo textures with
  // their mip levels (layout.h, BINDING_SURFACES); empty without textures.
  std::vector<glm::uvec4> surfaces;
  std::vector<glm::vec4> plate; // width x height, rgb; empty when the scene has none
  int width = 0;
  int height = 0;
  // The world point that primitives and lights are stored relative to: the
  // camera position rounded to a multiple of 64 m, so that a scene far from
  // the world origin keeps float precision (and small ray offsets) near the
  // camera, and a scene near it compiles exactly as given. FrameParams stay in
  // world coordinates; the tracers subtract this from cam_position.
  glm::vec3 origin{0.0f};
  // One entry per object that kept a primitive, in the scene's order.
  std::vector<ObjectBounds> objects;
};

// Flattens the objects (planes and boxes into triangles, meshes transformed
// into the world frame, spheres analytic), builds the BVH and the textures'
// mip levels.
[[nodiscard]] CompiledScene compile_scene(const Scene &scene);

// Frame parameters from the scene's camera and settings; samples <= 0 takes
// the scene's `render.samples`. The sample range covers all samples. A focus
// distance beyond 1e6 m, +infinity included, is focus at 1e6 m (the scene
// loader's limit); one that is not > 0 (or NaN) is a 1 m stand-in.
[[nodiscard]] gpu::FrameParams make_frame_params(const Scene &scene, int samples = 0);
// The same for a live frame's camera; the scene supplies the image size,
// render settings and lights.
[[nodiscard]] gpu::FrameParams make_frame_params(const Scene &scene, const FrameCamera &camera,
                                                 int samples = 0);

} // namespace camhead::renderer
