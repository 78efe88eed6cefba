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

} // namespace camhead::pipeline
