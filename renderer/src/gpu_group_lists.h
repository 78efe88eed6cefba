// The group lists (buffers.glsl, GROUP_LIST; layout.h, BINDING_GROUP_LIST):
// the workgroups a kernel runs over an influence region smaller than the
// frame, one dispatch each rather than one per rectangle.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "camhead/renderer/gpu_layout.h"
#include "camhead/renderer/influence_region.h"

namespace camhead::renderer {

// The 8x8 tiles of a width x height image.
[[nodiscard]] std::uint32_t tiles_of(std::uint32_t width, std::uint32_t height);

// A workgroup's place in a group list.
[[nodiscard]] std::uint32_t group_place(std::uint32_t x, std::uint32_t y);

// The 8x8 tiles of `region`, each once, appended to `places`.
void tile_places(const InfluenceRegion &region, std::vector<std::uint32_t> &places);

// The video kernels' workgroups (VIDEO_GROUP_X x VIDEO_GROUP_Y pixels) that
// `region` touches, each once, appended to `places`; `spans` is scratch.
void video_group_places(const InfluenceRegion &region, glm::uvec2 groups,
                        std::vector<glm::uvec2> &spans, std::vector<std::uint32_t> &places);

} // namespace camhead::renderer
