// A picture's luma codes to light, as the renderer decodes a camera's
// video (renderer/shaders/video.glsl: the range's normalisation, then
// sRGB's curve): the marker module reads and aligns the board in light.
// Inside libcamhead_markers.so only.
#pragma once

#include <opencv2/core.hpp>

namespace camhead::pipeline {

// The table that takes a picture's codes (LumaImage: sRGB over 16-235 or
// 0-255) to light on a 0..255 scale, as `depth` (CV_8U or CV_32F) for
// cv::LUT. A lens blurs light, and a camera codes it: sRGB's curve lifts a
// blurred edge's mid-tones, so that a dark marker looks smaller than it is
// and a blurred board is no blur of its page. On pictures coded as a
// camera codes them (tests/markers/synthetic_view.h), read as codes, a
// sharp board 2 m away seen low (23 degrees) read 17 of its 27 markers and
// gave a pose 2.8 mm off (0.6 mm in light), and aligned through 20 px of
// blur and more, the moving rig's board was 1.05 px off at the median (0.18
// px in light; bench/RESULTS.md, "Late frames and the first").
[[nodiscard]] cv::Mat light_table(bool limited_range, int depth);

} // namespace camhead::pipeline
