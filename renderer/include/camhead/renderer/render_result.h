// What a tracer returns for one frame: the composite and its layers.
#pragma once

#include <cstdint>
#include <functional>

#include "camhead/renderer/image.h"

namespace camhead::renderer {

struct RenderResult {
  Image composite;      // I_f = M I_m + (1 - M)(I_c + I_m - I_r); I_m where there is no plate
  Image mixed;          // I_m: real proxy and virtual objects
  Image real;           // I_r: real proxy alone
  Image mask;           // M: fraction of camera rays whose first hit is virtual (1 channel)
  Image depth;          // mean camera-axis depth of the hits, 0 where none (1 channel)
  double seconds = 0.0; // wall time of the render, excluding scene upload
  std::uint64_t camera_rays = 0; // width x height x samples
};

// Called between sample batches with the samples per pixel done so far.
using ProgressFn = std::function<void(int samples_done, int samples_total)>;

} // namespace camhead::renderer
