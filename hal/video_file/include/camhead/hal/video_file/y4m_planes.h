// Y4M stores a frame as whole planes, Y then Cb then Cr; camhead's formats
// interleave the chroma (nv12) or everything (yuyv). These convert between
// the two without resampling: 4:2:0 planes <-> nv12, 4:2:2 planes <-> yuyv.
// Any thread; no allocation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "camhead/base/video_format.h"

namespace camhead::hal::video_file {

// Bytes of one frame's planes for a yuyv or nv12 `format` (its stride aside).
[[nodiscard]] std::size_t y4m_plane_bytes(const base::VideoFormat &format);

// `format` is yuyv or nv12 and passes check_video_format; `planes` holds
// y4m_plane_bytes(format) bytes and `frame` frame_bytes(format). Padding
// bytes at the end of a strided row are left as they are.
void y4m_planes_to_frame(std::span<const std::uint8_t> planes, const base::VideoFormat &format,
                         std::span<std::uint8_t> frame);
void frame_to_y4m_planes(std::span<const std::uint8_t> frame, const base::VideoFormat &format,
                         std::span<std::uint8_t> planes);

} // namespace camhead::hal::video_file
