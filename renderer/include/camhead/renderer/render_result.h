// What a tracer returns for one frame: the composite and its layers.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "camhead/renderer/image.h"

namespace camhead::renderer {

// Where a frame's wall time went, for `camhead bench` (not part of any test).
struct FrameTimings {
  double trace_s = 0.0;   // sample batches: submit to fence, all batches
  double resolve_s = 0.0; // resolve kernel and the copy of the layers to host memory
  double unpack_s = 0.0;  // host: layers into Images
};

struct RenderResult {
  Image composite; // I_f = M I_m + (1 - M)(I_c + I_m - I_r); I_m where there is no plate
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
  // Adaptive sampling only: samples traced per pixel, row by row; else empty.
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

  static constexpr LayerSelection all() { return {}; }
  static constexpr LayerSelection display_only() { return {false, false, false, false, true}; }
};

// Called between sample batches with the samples per pixel done so far.
using ProgressFn = std::function<void(int samples_done, int samples_total)>;

} // namespace camhead::renderer
