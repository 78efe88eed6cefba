// The Vulkan compute tracer. Vulkan types stay behind this interface.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/render_result.h"

namespace camhead::renderer {

class GpuError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

struct GpuDeviceInfo {
  int index = 0;
  std::string name;
  std::string type; // "cpu", "discrete", "integrated", "virtual", "other"
};

// Lists the Vulkan devices that can run the tracer (compute queue present).
[[nodiscard]] std::vector<GpuDeviceInfo> list_gpu_devices();

// One line per device, "  <index>: <name> (<type>)", for listings and errors.
[[nodiscard]] std::string format_gpu_devices(const std::vector<GpuDeviceInfo> &devices);

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

  // Traces frame.sampling.z samples per pixel in batches, calling `progress`
  // after each, resolves the layers and the composite on the GPU and reads
  // them back.
  [[nodiscard]] RenderResult render(const gpu::FrameParams &frame, const ProgressFn &progress = {},
                                    LayerSelection layers = LayerSelection::all());

  // Adaptive sampling (adaptive.h): frame.sampling.z samples per pixel on
  // average, shared out by what a pilot saw; result.sample_counts holds the
  // shares. The same steps as render_cpu_adaptive().
  [[nodiscard]] RenderResult render_adaptive(const gpu::FrameParams &frame,
                                             const AdaptiveSampling &settings = {},
                                             const ProgressFn &progress = {},
                                             LayerSelection layers = LayerSelection::all());

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace camhead::renderer
