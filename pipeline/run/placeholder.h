// The picture the outputs show while there is no camera frame to composite.
#pragma once

#include <cstdint>
#include <span>

#include "camhead/base/video_format.h"

namespace camhead::pipeline {

// A frame nobody should mistake for a picture or for a broken one (a
// zero-filled YUV frame is green): mid grey with a darker band a fifth of
// the height across the middle.
void fill_placeholder(const base::VideoFormat &f, std::span<std::uint8_t> out);

} // namespace camhead::pipeline
