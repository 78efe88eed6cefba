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

// Whether `frame` has a lens model beyond the ideal pinhole (TRACING_LENS_MODEL).
[[nodiscard]] bool has_lens_model(const gpu::FrameParams &frame);
// The lens model's two directions (renderer/shaders/lens_model.glsl, the
// same arithmetic): from a point of the ideal image plane (normalised: x
// right, y down, z = 1 ahead of the pupil) to the pixel where the frame's
// lens puts it, and from a pixel back. Without a lens model, the pinhole's.
[[nodiscard]] glm::vec2 ideal_to_pixel(const gpu::FrameParams &frame, glm::vec2 ideal);
[[nodiscard]] glm::vec2 pixel_to_ideal(const gpu::FrameParams &frame, glm::vec2 pixel);

// How far the frame's view reaches on the ideal image plane, and how much
// its lens model stretches it: the largest distance from the axis of a
// pixel's preimage (the border, every 4 pixels), and the largest spectral
// norm of the lens's Jacobian (pixels of the image per pixel of the ideal
// plane) on a grid over the preimage's bounds grown by `margin` (ideal
// plane units: what lies that far outside the view, a blur circle's rim,
// still reaches into it), and the smallest singular value there; and the
// most the lens moves a point up or down from where the pinhole of its
// principal point and focal lengths would put it (the grid's largest, a
// tenth more), in pixels. A pinhole's: the half-diagonal over the focal
// length, 1, 1 and 0.
struct LensExtent {
  double max_tan = 0.0;
  double stretch = 1.0;
  double least_stretch = 1.0;
  double max_row_shift_px = 0.0;
};
[[nodiscard]] LensExtent lens_extent(const gpu::FrameParams &frame, double margin = 0.0);
[[nodiscard]] glm::uvec2 image_size(const gpu::FrameParams &frame);

// Where a world point lands in the image, pixels from the top left (through
// the pinhole, or the lens model where the frame has one: the centre of its
// blur circle); none behind the lens.
[[nodiscard]] std::optional<glm::vec2> project_to_pixel(const gpu::FrameParams &frame,
                                                        glm::vec3 world);

} // namespace camhead::renderer
