// The scene flattened into the buffers that the tracers read (layout.h):
// primitives in BVH order, BVH nodes, materials, lights and the plate.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec4.hpp>

#include "camhead/renderer/gpu_layout.h"
#include "camhead/renderer/scene.h"

namespace camhead::renderer {

struct CompiledScene {
  std::vector<gpu::Primitive> primitives; // ordered as the BVH leaves use them
  std::vector<gpu::BvhNode> nodes;        // nodes[0] is the root
  std::vector<gpu::Material> materials;
  std::vector<gpu::Light> lights;
  std::vector<glm::vec4> plate; // width x height, rgb; empty when the scene has none
  int width = 0;
  int height = 0;
};

// Flattens the objects (planes and boxes into triangles, meshes transformed
// into the world frame, spheres analytic) and builds the BVH.
[[nodiscard]] CompiledScene compile_scene(const Scene &scene);

// Frame parameters from the scene's camera and settings; samples <= 0 takes
// the scene's `render.samples`. The sample range covers all samples.
[[nodiscard]] gpu::FrameParams make_frame_params(const Scene &scene, int samples = 0);

} // namespace camhead::renderer
