// C++ view of renderer/shaders/layout.h: the GLSL buffer structs in glm types.
#pragma once

#include <cstdint>

#include <glm/vec4.hpp>

namespace camhead::renderer::gpu {

using glm::uvec4;
using glm::vec4;
using uint = std::uint32_t;

#include "layout.h" // renderer/shaders/layout.h, shared with GLSL

static_assert(sizeof(Primitive) == 48);
static_assert(sizeof(BvhNode) == 32);
static_assert(sizeof(Material) == 32);
static_assert(sizeof(Light) == 80);
static_assert(sizeof(FrameParams) == 13 * 16);
static_assert(sizeof(AdaptiveSolution) == 2 * 16);
static_assert(sizeof(VideoFrames) == (2 * (1 + VIDEO_MAX_OUTPUTS) + 1) * 16);

} // namespace camhead::renderer::gpu
