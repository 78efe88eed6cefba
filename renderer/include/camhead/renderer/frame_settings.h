// A frame's settings by name, for the code outside the renderer that sets
// up frames (the render, bench and chart commands): what the kernels read
// from the std140 FrameParams (gpu_layout.h), which fields and which flags
// packed into them, stays the renderer's business. Start from
// make_frame_params() (compiled_scene.h).
#pragma once

#include <cstdint>
#include <optional>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/gpu_layout.h"

namespace camhead::renderer {

// How camera rays sample the pixel and the lens (sampling.glsl): correlated
// multi-jittered (the default, a fixed count) or Owen-scrambled Sobol' (a
// progressive pattern).
enum class CameraSampler { cmj, sobol };
void set_camera_sampler(gpu::FrameParams &frame, CameraSampler sampler);

// One sample, not the frame's count, for a pixel whose first sample meets
// nothing virtual and no virtual shadow (kernel.glsl).
void set_skip_empty_pixels(gpu::FrameParams &frame, bool on);

// No aperture: everything in focus.
void set_pinhole(gpu::FrameParams &frame);

// Whether the composite goes over a plate (the camera image) or is I_m.
void set_has_plate(gpu::FrameParams &frame, bool has_plate);

// The frame's noise pattern: another seed, independent noise.
[[nodiscard]] std::uint32_t seed(const gpu::FrameParams &frame);
void set_seed(gpu::FrameParams &frame, std::uint32_t seed);

[[nodiscard]] std::uint32_t rays_per_pixel(const gpu::FrameParams &frame);
[[nodiscard]] glm::uvec2 image_size(const gpu::FrameParams &frame);

// Where a world point lands in the image, pixels from the top left (its
// pinhole projection, the centre of its blur circle); none behind the lens.
[[nodiscard]] std::optional<glm::vec2> project_to_pixel(const gpu::FrameParams &frame,
                                                        glm::vec3 world);

} // namespace camhead::renderer
