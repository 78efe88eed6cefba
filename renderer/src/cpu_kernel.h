// The C++ executor of renderer/shaders/kernel.glsl.
//
// The kernel is included inside CpuKernel, so its "global" buffers become
// member pointers and its functions member functions; glm supplies the GLSL
// vocabulary. One model, two executors: the CPU reference traces exactly the
// rays the GPU traces.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
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

  // GLSL's bitfieldReverse for the sampler's scrambles, which call it five
  // times a sample: glm's generic one is a loop of templated steps that
  // only -O2 flattens, and the sanitizer build (which runs the CPU
  // reference at -O1) spent a third of its tracing in it. Found by class
  // scope before glm's.
  static constexpr uint bitfieldReverse(uint x) {
    x = ((x >> 1u) & 0x55555555u) | ((x & 0x55555555u) << 1u);
    x = ((x >> 2u) & 0x33333333u) | ((x & 0x33333333u) << 2u);
    x = ((x >> 4u) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4u);
    x = ((x >> 8u) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8u);
    return (x >> 16u) | (x << 16u);
  }

  // GLSL's findLSB for the Sobol' loop, which calls it once a set bit of a
  // scrambled index (some 16 a dimension triple): glm's counts the bits
  // below the lowest in five steps of masks, where the CPU has one
  // instruction (bsf or tzcnt). Found by class scope before glm's.
  static constexpr int findLSB(uint x) { return x == 0u ? -1 : std::countr_zero(x); }

  // A pass's Sobol' points, before the pixels' keys (sampling.glsl): every
  // pixel takes the same point at sample s, so the frame renderer makes
  // them once for the pass of seed `sobol_points_seed` rather than once a
  // pixel, which at one ray a pixel saves about what the keys cost
  // (bench/RESULTS.md, "Sobol' keys in Z order"). Past the table, or in
  // another pass (the adaptive second pass), the kernel makes its own.
  const glm::uvec4 *sobol_points = nullptr;
  uint sobol_points_count = 0;
  uint sobol_points_seed = 0;
  [[nodiscard]] glm::uvec4 sobol_pass_point(uint s, uint seed) {
    if (s < sobol_points_count && seed == sobol_points_seed)
      return sobol_points[s];
    return sobol_scrambled_point(s, seed);
  }

#define CAMHEAD_SOBOL_PASS_TABLE
#include "kernel.glsl"
#undef CAMHEAD_SOBOL_PASS_TABLE
};

static_assert(CpuKernel::bitfieldReverse(0x00000001u) == 0x80000000u);
static_assert(CpuKernel::bitfieldReverse(0x12345678u) == 0x1e6a2c48u);
static_assert(CpuKernel::bitfieldReverse(0xf0000001u) == 0x8000000fu);
static_assert(CpuKernel::findLSB(0u) == -1 && CpuKernel::findLSB(1u) == 0);
static_assert(CpuKernel::findLSB(0x80000000u) == 31 && CpuKernel::findLSB(0x00f0a800u) == 11);

#undef INOUT
#undef OUT
#undef PRECISE
#undef KERNEL_TABLE

// A pass's Sobol' points for a kernel (CpuKernel::sobol_points), made once
// for a seed, and only the new ones for a longer pattern (a history's seed
// stays while it goes on); at most `capacity`.
class SobolPointTable {
public:
  explicit SobolPointTable(std::size_t capacity) : points_(capacity) {}
  // Gives `kernel` the points of `frame`'s pass, none unless it samples
  // with Sobol'.
  void give(CpuKernel &kernel, const FrameParams &frame) {
    kernel.sobol_points = nullptr;
    kernel.sobol_points_count = 0;
    if (frame.tracing.z != SAMPLER_SOBOL)
      return;
    const auto count = std::uint32_t(std::min<std::size_t>(frame.sampling.z, points_.size()));
    if (frame.sampling.w != seed_)
      count_ = 0;
    for (std::uint32_t s = count_; s < count; ++s)
      points_[s] = kernel.sobol_scrambled_point(s, frame.sampling.w);
    seed_ = frame.sampling.w;
    count_ = std::max(count_, count);
    kernel.sobol_points = points_.data();
    kernel.sobol_points_count = count_;
    kernel.sobol_points_seed = seed_;
  }

private:
  std::vector<glm::uvec4> points_;
  std::uint32_t seed_ = 0, count_ = 0;
};

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
