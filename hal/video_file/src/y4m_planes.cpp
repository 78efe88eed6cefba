// Planar Y4M frames to and from nv12 / yuyv; see y4m_planes.h.
#include "camhead/hal/video_file/y4m_planes.h"

#include <cassert>
#include <cstring>

namespace camhead::hal::video_file {
namespace {

struct Planes {
  std::size_t width, height;             // luma
  std::size_t chroma_width, chroma_rows; // each of Cb, Cr
  std::size_t stride;                    // of the packed frame
};

Planes planes_of(const base::VideoFormat &format) {
  assert(base::check_video_format(format).empty() && base::is_yuv(format.pixel));
  const auto width = static_cast<std::size_t>(format.width);
  const auto height = static_cast<std::size_t>(format.height);
  const bool nv12 = format.pixel == base::PixelFormat::nv12;
  return {width, height, width / 2, nv12 ? height / 2 : height, base::row_bytes(format)};
}

} // namespace

std::size_t y4m_plane_bytes(const base::VideoFormat &format) {
  const Planes p = planes_of(format);
  return p.width * p.height + 2 * p.chroma_width * p.chroma_rows;
}

void y4m_planes_to_frame(std::span<const std::uint8_t> planes, const base::VideoFormat &format,
                         std::span<std::uint8_t> frame) {
  const Planes p = planes_of(format);
  assert(planes.size() == y4m_plane_bytes(format) && frame.size() == base::frame_bytes(format));
  const std::uint8_t *y = planes.data();
  const std::uint8_t *cb = y + p.width * p.height;
  const std::uint8_t *cr = cb + p.chroma_width * p.chroma_rows;
  if (format.pixel == base::PixelFormat::nv12) {
    for (std::size_t row = 0; row < p.height; ++row)
      std::memcpy(frame.data() + row * p.stride, y + row * p.width, p.width);
    std::uint8_t *uv = frame.data() + p.stride * p.height;
    for (std::size_t row = 0; row < p.chroma_rows; ++row) {
      std::uint8_t *out = uv + row * p.stride;
      for (std::size_t i = 0; i < p.chroma_width; ++i) {
        out[2 * i] = cb[row * p.chroma_width + i];
        out[2 * i + 1] = cr[row * p.chroma_width + i];
      }
    }
    return;
  }
  for (std::size_t row = 0; row < p.height; ++row) {
    std::uint8_t *out = frame.data() + row * p.stride;
    const std::uint8_t *y_row = y + row * p.width;
    for (std::size_t i = 0; i < p.chroma_width; ++i) {
      out[4 * i] = y_row[2 * i];
      out[4 * i + 1] = cb[row * p.chroma_width + i];
      out[4 * i + 2] = y_row[2 * i + 1];
      out[4 * i + 3] = cr[row * p.chroma_width + i];
    }
  }
}

void frame_to_y4m_planes(std::span<const std::uint8_t> frame, const base::VideoFormat &format,
                         std::span<std::uint8_t> planes) {
  const Planes p = planes_of(format);
  assert(planes.size() == y4m_plane_bytes(format) && frame.size() == base::frame_bytes(format));
  std::uint8_t *y = planes.data();
  std::uint8_t *cb = y + p.width * p.height;
  std::uint8_t *cr = cb + p.chroma_width * p.chroma_rows;
  if (format.pixel == base::PixelFormat::nv12) {
    for (std::size_t row = 0; row < p.height; ++row)
      std::memcpy(y + row * p.width, frame.data() + row * p.stride, p.width);
    const std::uint8_t *uv = frame.data() + p.stride * p.height;
    for (std::size_t row = 0; row < p.chroma_rows; ++row) {
      const std::uint8_t *in = uv + row * p.stride;
      for (std::size_t i = 0; i < p.chroma_width; ++i) {
        cb[row * p.chroma_width + i] = in[2 * i];
        cr[row * p.chroma_width + i] = in[2 * i + 1];
      }
    }
    return;
  }
  for (std::size_t row = 0; row < p.height; ++row) {
    const std::uint8_t *in = frame.data() + row * p.stride;
    std::uint8_t *y_row = y + row * p.width;
    for (std::size_t i = 0; i < p.chroma_width; ++i) {
      y_row[2 * i] = in[4 * i];
      cb[row * p.chroma_width + i] = in[4 * i + 1];
      y_row[2 * i + 1] = in[4 * i + 2];
      cr[row * p.chroma_width + i] = in[4 * i + 3];
    }
  }
}

} // namespace camhead::hal::video_file
