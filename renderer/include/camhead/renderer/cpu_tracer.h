// The CPU reference tracer: the same kernel code (renderer/shaders/kernel.glsl)
// compiled as C++, run on std::threads. Tests compare it with the GPU tracer.
#pragma once

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/render_result.h"

namespace camhead::renderer {

// threads <= 0: one per hardware thread.
[[nodiscard]] RenderResult render_cpu(const CompiledScene &scene, const gpu::FrameParams &frame,
                                      const ProgressFn &progress = {}, int threads = 0);

// Adaptive sampling (adaptive.h): frame.sampling.z samples per pixel on
// average, shared out by what a pilot saw. result.sample_counts holds the
// shares.
[[nodiscard]] RenderResult render_cpu_adaptive(const CompiledScene &scene,
                                               const gpu::FrameParams &frame,
                                               const AdaptiveSampling &settings = {},
                                               const ProgressFn &progress = {}, int threads = 0);

} // namespace camhead::renderer
