// The chart's measures of a frame against its reference
// (chart_command.cpp): relative RMSE, the depth edges where defocus methods
// fail, and the box average that brings a finer reference to a frame's size.
#pragma once

#include <cstdint>
#include <vector>

#include "camhead/renderer/image.h"

namespace camhead::cli {

// Relative RMSE as compare.py defines it (RMSE / RMS(reference)), over the
// pixels where `mask` is set (all pixels when it is empty). Throws
// std::runtime_error for images of different sizes.
[[nodiscard]] double relative_rmse(const renderer::Image &reference, const renderer::Image &test,
                                   const std::vector<std::uint8_t> &mask = {});

// Pixels within `radius` of a depth discontinuity of a pinhole depth layer
// (0 = nothing hit): where a hit meets a miss, or where the depth jumps by
// more than 5% between neighbours and by more than 3x the neighbouring steps
// along the same line (so that a receding plane's steady gradient is no edge).
[[nodiscard]] std::vector<std::uint8_t> depth_edge_mask(const renderer::Image &depth, int radius);

// Box average of `image` over k x k blocks.
[[nodiscard]] renderer::Image box_downsample(const renderer::Image &image, int k);

} // namespace camhead::cli
