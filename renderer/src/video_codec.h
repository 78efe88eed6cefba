// Camera frames into the linear plate, and the linear composite into output
// frames, row by row on the CPU: renderer/shaders/video.glsl compiled as C++.
// The row functions are what the frame renderer's threads run in parallel.
#pragma once

#include <cstdint>
#include <span>

#include <glm/vec4.hpp>

#include "camhead/base/video_format.h"

namespace camhead::renderer::video {

// Columns [x0, x1) of row `y` of `frame` (format `format`, every plane) as
// linear RGB into `out[x0..x1)`, w = 0; x1 < 0 is the width. x0 and x1 are
// even (a yuyv or nv12 chroma sample spans two columns). The caller has
// checked the format and the size.
void decode_row(const base::VideoFormat &format, std::span<const std::uint8_t> frame, int y,
                glm::vec4 *out, int x0 = 0, int x1 = -1);

// Columns [x0, x1) of the rows [y0, y1) of `image` (linear RGB, width x
// height, row-major) into `frame`; x1 < 0 is the width, x0 and x1 even. For
// nv12, y0 is even and y1 even or the height: a chroma row is the mean of
// two image rows.
void encode_rows(const base::VideoFormat &format, std::span<std::uint8_t> frame,
                 const glm::vec4 *image, int y0, int y1, int x0 = 0, int x1 = -1);

// Row `row` of every plane (base::frame_rows) of `from` into `to`, frames
// of the same pixel format and width (their strides may differ).
void copy_row(const base::VideoFormat &from_format, std::span<const std::uint8_t> from,
              const base::VideoFormat &to_format, std::span<std::uint8_t> to, int row);

} // namespace camhead::renderer::video
