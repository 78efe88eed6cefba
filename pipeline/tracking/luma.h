// A camera frame's luma plane, as the marker tracker reads it: Y' as
// captured for the Y'CbCr formats (no colour conversion), BT.601 weights for
// the RGB ones. Copied out so that the camera's buffer goes back at once and
// the tracker can work while the frame renders.
#pragma once

#include <cstdint>
#include <span>

#include "camhead/base/video_format.h"

namespace camhead::pipeline {

// Writes format.width x format.height bytes, rows packed, into `out`
// (at least that large). Allocates nothing.
void copy_luma(const base::VideoFormat &format, std::span<const std::uint8_t> frame,
               std::span<std::uint8_t> out);

// Whether copy_luma's codes for `format` span 16-235 (Y'CbCr video in the
// limited range) rather than 0-255 (full range, and the RGB formats).
[[nodiscard]] bool luma_limited_range(const base::VideoFormat &format);

// Limited-range codes (16-235) stretched, in place, over the full range
// (0-255), as an 8-bit grey picture file has them.
void luma_to_full_range(std::span<std::uint8_t> luma);

} // namespace camhead::pipeline
