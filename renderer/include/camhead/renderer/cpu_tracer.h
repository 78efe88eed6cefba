// The CPU reference tracer: the same kernel code (renderer/shaders/kernel.glsl)
// compiled as C++, run on std::threads. Tests compare it with the GPU tracer.
#pragma once

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/influence_region.h"
#include "camhead/renderer/render_result.h"

namespace camhead::renderer {

// threads <= 0: one per hardware thread. With a `region`
// (influence_region.h) only its pixels are traced: the composite is the
// same, the other layers are zero outside it.
[[nodiscard]] RenderResult render_cpu(const CompiledScene &scene, const gpu::FrameParams &frame,
                                      const ProgressFn &progress = {}, int threads = 0,
                                      const InfluenceRegion *region = nullptr);

// Adaptive sampling (adaptive.h): frame.sampling.z samples per pixel on
// average, shared out by what a pilot saw. result.sample_counts holds the
// shares. With a `region`, the region's pixels share its pixels' budget
// (adaptive.h) and the rest get none.
[[nodiscard]] RenderResult render_cpu_adaptive(const CompiledScene &scene,
                                               const gpu::FrameParams &frame,
                                               const AdaptiveSampling &settings = {},
                                               const ProgressFn &progress = {}, int threads = 0,
                                               const InfluenceRegion *region = nullptr);

} // namespace camhead::renderer
