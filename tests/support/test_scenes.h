// Small scenes built in code for the physics tests.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/scene.h"

namespace camhead::test {

// A camera at the origin looking down -Z (f = 50 mm, 36 mm sensor) at a
// radiance-1 emitter that fills the half-plane x > 0 at depth `depth_m`,
// against a black world: a vertical edge on the image's centre column.
[[nodiscard]] renderer::Scene edge_scene(float f_number, float focus_m, float depth_m,
                                         int width = 256, int height = 16);

// The thin-lens blur-circle diameter in pixels (scene-format.md):
// CoC_px = f_px * (f / N) * |1/d_f - 1/d|.
[[nodiscard]] double coc_px(const renderer::Scene &scene, float depth_m);

// Pixel position of a world point through the pinhole of the scene camera.
[[nodiscard]] glm::vec2 project(const renderer::Scene &scene, glm::vec3 world);

} // namespace camhead::test
