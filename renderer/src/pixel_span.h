// A row's stretch of pixels: how the CPU frame renderer walks its influence
// region, and the passes that work on it (defocus_filter.h, ray_shares.h).
#pragma once

#include <cstdint>

namespace camhead::renderer::cpu {

// Pixels [x0, x1) of row y.
struct PixelSpan {
  std::uint32_t y, x0, x1;
};

} // namespace camhead::renderer::cpu
