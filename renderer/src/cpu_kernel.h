// The C++ executor of renderer/shaders/kernel.glsl.
//
// The kernel is included inside CpuKernel, so its "global" buffers become
// member pointers and its functions member functions; glm supplies the GLSL
// vocabulary. One model, two executors: the CPU reference traces exactly the
// rays the GPU traces.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/integer.hpp>
#include <glm/packing.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/gpu_layout.h"

namespace camhead::renderer::cpu {

using namespace glm; // the GLSL built-ins the kernel calls unqualified
using gpu::BvhNode;
using gpu::FrameParams;
using gpu::Light;
using gpu::Material;
using gpu::Primitive;
using uint = std::uint32_t;

#define INOUT(T) T &
#define OUT(T) T &
#define PRECISE                       // C++ without -ffast-math keeps the order as written
#define KERNEL_TABLE static constexpr // a constant array, a member of the struct
#define CAMHEAD_PI 3.14159265358979f

struct CpuKernel {
  const Primitive *primitives = nullptr;
  const BvhNode *nodes = nullptr;
  const Material *materials = nullptr;
  const Light *lights = nullptr;
  const glm::uvec4 *surfaces = nullptr; // texture coordinates and textures (layout.h)
  const uint *sample_counts = nullptr;  // adaptive second pass only (tracing.y > 0)
  FrameParams frame{};
  // Every feature, chosen at run time (layout.h).
  static constexpr uint KERNEL_FEATURES = KERNEL_ALL;

  // The GLSL kernel reads the scene through texel buffers (buffers.glsl).
  [[nodiscard]] Primitive primitive_at(uint index) const { return primitives[index]; }
  [[nodiscard]] BvhNode node_at(uint index) const { return nodes[index]; }
  [[nodiscard]] Material material_at(uint index) const { return materials[index]; }
  [[nodiscard]] Light light_at(uint index) const { return lights[index]; }
  [[nodiscard]] glm::uvec4 surface_texel_at(uint texel) const { return surfaces[texel]; }

#include "kernel.glsl"
};

#undef INOUT
#undef OUT
#undef PRECISE
#undef KERNEL_TABLE

// The kernel as the CPU reference runs it: `scene` with `frame` moved into
// the compiled scene's frame, uniform sampling (tracing.y = 0), pixels no
// ray can take into the scene traced once (TRACING_SKIP_EMPTY_PIXELS).
// `nodes` keeps the BVH alive (the empty one for a scene without nodes).
[[nodiscard]] CpuKernel make_cpu_kernel(const CompiledScene &scene, const FrameParams &frame,
                                        std::vector<BvhNode> &nodes);

// The frame part of make_cpu_kernel() alone, for a kernel that renders frame
// after frame of one scene.
void set_cpu_frame(CpuKernel &kernel, const CompiledScene &scene, const FrameParams &frame);

} // namespace camhead::renderer::cpu
