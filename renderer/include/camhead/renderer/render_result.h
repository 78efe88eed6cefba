// What a tracer returns for one frame: the composite and its layers.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "camhead/renderer/image.h"

namespace camhead::renderer {

// Where a frame's time went, for `camhead bench` and the chart (not part of
// any test). GPU tracer only.
struct FrameTimings {
  // Device timestamps from the frame's first command to its last copy into
  // host memory: the frame's cost on the device, without the latency of
  // submitting and waiting (between submissions, that latency is included).
  // 0 where the device has no timestamps.
  double device_s = 0.0;
  // Adaptive frames: the allocation kernels between the passes, by the same
  // timestamps (part of device_s).
  double allocation_s = 0.0;
  double submit_s = 0.0; // host: from the call to the last fence, all submissions
  double unpack_s = 0.0; // host: layers into Images
  int submissions = 0;   // one per batch; a frame of one batch is one submission
};

struct RenderResult {
  Image composite; // I_f = M I_m + (1 - M)(I_c + I_m - I_r), not below black where I_c is
                   // not (kernel.glsl); I_m where there is no plate
  Image mixed;     // I_m: real proxy and virtual objects
  Image real;      // I_r: real proxy alone
  Image mask;      // M: fraction of camera rays whose first hit is virtual (1 channel)
  Image depth;     // mean camera-axis depth of the hits, 0 where none (1 channel)
  // The composite as displays and V4L2 sinks take it: 4 bytes per pixel, row
  // by row, R G B sRGB-encoded as write_png() does (within one code value),
  // A = round(255 M). GPU tracer only; the CPU reference leaves it empty.
  std::vector<std::uint8_t> display;
  double seconds = 0.0;          // wall time of the render, excluding scene upload
  std::uint64_t camera_rays = 0; // width x height x samples (adaptive: the sum of sample_counts)
  // Adaptive sampling only: samples traced per pixel, row by row; else (and
  // from the GPU tracer when not selected) empty.
  std::vector<std::uint32_t> sample_counts;
  FrameTimings timings; // GPU tracer only
};

// Which layers a caller wants back from the GPU tracer. Reading a float
// layer back costs host time in proportion to the image (bench/RESULTS.md: on
// an H100 it was most of the frame), so a live frame asks for the 8-bit
// display image alone. Layers not asked for come back empty.
struct LayerSelection {
  bool composite = true;
  bool mixed = true;
  bool real = true;
  bool mask_and_depth = true;
  bool display = true;
  bool sample_counts = true; // adaptive sampling only

  static constexpr LayerSelection all() { return {}; }
  static constexpr LayerSelection display_only() {
    return {false, false, false, false, true, false};
  }
};

// Called between sample batches with the samples per pixel done so far.
using ProgressFn = std::function<void(int samples_done, int samples_total)>;

} // namespace camhead::renderer
