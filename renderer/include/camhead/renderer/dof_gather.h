// Image-space depth of field, the baseline the thin-lens tracer is charted
// against (bench/RESULTS.md, `camhead bench chart`): a pinhole render blurred
// by a depth-driven gather with the circle of confusion of method.md section 1
// (renderer/shaders/dof_gather.comp explains the weights). Vulkan types stay
// behind this interface, as for GpuTracer.
//
// Thread safety: a DofGather is used by one thread at a time.
#pragma once

#include <memory>
#include <span>
#include <string>

#include <glm/vec4.hpp>

#include "camhead/renderer/gpu_layout.h"
#include "camhead/renderer/render_result.h"

namespace camhead::renderer {

// Blur radius in pixels of a point at camera-axis depth `depth` (m; <= 0 =
// nothing hit, infinitely far) under the thin lens of `lens` (its aperture
// radius lens.x, focus depth lens.y, focal length in pixels lens.z): half of
// method.md's c = 2R p |z - d_f| / (z d_f). The shader's formula, on the host.
[[nodiscard]] float coc_radius_px(const gpu::FrameParams &lens, float depth);

struct DofGatherSettings {
  // Largest blur radius gathered (px); the cost grows with its square. 0 =
  // the radius of the nearest and the farthest depth of the input (host pass).
  float max_radius_px = 0.0f;
  // A neighbour less than this fraction nearer than a pixel counts as lying
  // at its depth (same surface), not in front of it.
  float depth_tolerance = 0.02f;
};

struct DofGatherResult {
  RenderResult image;       // composite, mixed, real, mask, depth (the input's)
  double gather_s = 0;      // the gather kernel alone: submit to fence, data on the device
  double device_s = 0;      // the same by device timestamps; 0 without timestamps
  double max_radius_px = 0; // the radius gathered
};

class DofGather {
public:
  // `device` as for GpuTracer: empty = the first discrete or integrated GPU,
  // else the first device; a number = that index; anything else = the first
  // device whose name contains it (pass GpuTracer::device_name() to share
  // the tracer's GPU). Throws GpuError.
  explicit DofGather(const std::string &device = {});
  ~DofGather();
  DofGather(const DofGather &) = delete;
  DofGather &operator=(const DofGather &) = delete;

  [[nodiscard]] std::string device_name() const;

  // Blurs `pinhole` (its mixed, real, mask and depth layers, as a GpuTracer or
  // render_cpu() returns them for a frame with lens.x = 0) as the thin lens
  // of `lens` would, and composites with `plate` (I_c, width x height, or
  // empty: then the composite is the blurred I_m). Throws GpuError.
  [[nodiscard]] DofGatherResult apply(const RenderResult &pinhole, const gpu::FrameParams &lens,
                                      std::span<const glm::vec4> plate = {},
                                      const DofGatherSettings &settings = {});

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace camhead::renderer
