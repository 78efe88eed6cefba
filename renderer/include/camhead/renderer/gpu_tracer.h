// The Vulkan compute tracer. Vulkan types stay behind this interface.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/gpu_devices.h"
#include "camhead/renderer/gpu_error.h"
#include "camhead/renderer/influence_region.h"
#include "camhead/renderer/render_result.h"

namespace camhead::renderer {

class GpuTracer {
public:
  // `device`: empty = the first discrete or integrated GPU, else the first
  // device (lavapipe on machines without a GPU); a number = that index;
  // anything else = the first device whose name contains it. Throws GpuError.
  explicit GpuTracer(const std::string &device = {});
  ~GpuTracer();
  GpuTracer(const GpuTracer &) = delete;
  GpuTracer &operator=(const GpuTracer &) = delete;

  [[nodiscard]] std::string device_name() const;

  // Uploads geometry, materials, lights and plate. Must precede render().
  void load(const CompiledScene &scene);

  // The trace kernel is built for the features the loaded scene and the
  // frame use (layout.h, KERNEL_*), the driver dropping the code of the
  // others; `on` = false builds it with every feature, as the CPU reference
  // has them. The images are the same bit for bit
  // (tests/renderer/kernel_specialization_test.cpp); only the time differs,
  // which `camhead bench --every-kernel-feature` measures.
  void set_kernel_specialization(bool on);

  // Traces frame.sampling.z samples per pixel in batches, calling `progress`
  // after each, resolves the layers and the composite on the GPU and reads
  // them back. Every call takes an optional influence `region`
  // (influence_region.h, for this frame and the loaded scene): only its
  // pixels are traced, and the layers other than the composite are zero
  // outside it.
  [[nodiscard]] RenderResult render(const gpu::FrameParams &frame, const ProgressFn &progress = {},
                                    LayerSelection layers = LayerSelection::all(),
                                    const InfluenceRegion *region = nullptr);

  // Adaptive sampling (adaptive.h): frame.sampling.z samples per pixel on
  // average, shared out by what a pilot saw; result.sample_counts holds the
  // shares. The same steps as render_cpu_adaptive().
  [[nodiscard]] RenderResult render_adaptive(const gpu::FrameParams &frame,
                                             const AdaptiveSampling &settings = {},
                                             const ProgressFn &progress = {},
                                             LayerSelection layers = LayerSelection::all(),
                                             const InfluenceRegion *region = nullptr);

  // A live frame (frame_renderer.h): `plate` in its own pixel format is
  // converted into the linear plate on the device, and the composite into
  // each of `outputs` (at most VIDEO_MAX_OUTPUTS, layout.h); nothing else is
  // read back. Sizes as the loaded scene, width a multiple of 4 (the kernels
  // work on 4 x 2 blocks); the caller checks. A plate without bytes is none.
  //
  // `samples` [first, end) of the frame's pattern of frame.sampling.z
  // samples (CMJ or Sobol': any prefix is unbiased) add to those that the
  // frames before left in the accumulators when first > 0, and the
  // composite is the mean of samples [0, end): the frame before must have
  // been render_video() of the same loaded scene, camera, pattern, region,
  // outputs and `composite`, ending at `first`. Without it, samples [0,
  // frame.sampling.z), afresh. Not with `adaptive`. A frame whose
  // frame.reconstruct.x > 0 is reconstructed (layout.h; not with
  // `adaptive`); one that adds no sample (first == end) takes the first
  // passes of the frame before where that one ran them with the same
  // frame.reconstruct. With `composite`, the float composite comes back
  // too (RenderResult::composite), for measurement.
  struct SampleRange {
    std::uint32_t first = 0, end = 0;
  };
  [[nodiscard]] RenderResult render_video(const gpu::FrameParams &frame, const VideoFrame &plate,
                                          std::span<const VideoBuffer> outputs,
                                          const AdaptiveSampling *adaptive = nullptr,
                                          const InfluenceRegion *region = nullptr,
                                          std::optional<SampleRange> samples = std::nullopt,
                                          bool composite = false);

  // Builds every pipeline render_video() takes for frames like `frame`
  // with a camera frame in `plate` (none: no decode) and outputs in
  // `outputs`, over a region or the whole frame, adaptive or not: so that
  // no live frame compiles one.
  void prepare_video(const gpu::FrameParams &frame, std::optional<base::PixelFormat> plate,
                     std::span<const base::PixelFormat> outputs, bool adaptive);

private:
  struct VideoJob {
    VideoFrame plate;
    std::span<const VideoBuffer> outputs;
    SampleRange samples;
  };
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace camhead::renderer
