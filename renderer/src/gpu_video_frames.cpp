// See gpu_video_frames.h.
#include "gpu_video_frames.h"

#include <cstring>

namespace camhead::renderer {

VkDeviceSize max_video_bytes(std::size_t pixels) {
  return VkDeviceSize(4) * pixels;
}

std::uint32_t video_format_code(base::PixelFormat pixel) {
  switch (pixel) {
  case base::PixelFormat::yuyv:
    return VIDEO_YUYV;
  case base::PixelFormat::nv12:
    return VIDEO_NV12;
  case base::PixelFormat::rgb24:
    return VIDEO_RGB24;
  case base::PixelFormat::bgr24:
    return VIDEO_BGR24;
  case base::PixelFormat::xrgb8888:
    return VIDEO_XRGB8888;
  }
  return VIDEO_YUYV;
}

gpu::VideoParams video_params(const base::VideoFormat &f, std::uint32_t first_word) {
  gpu::VideoParams v{};
  v.format = gpu::uvec4(video_format_code(f.pixel), f.matrix == base::ColorMatrix::bt601 ? 0u : 1u,
                        f.range == base::ColorRange::full ? 1u : 0u, first_word);
  v.size = gpu::uvec4(std::uint32_t(f.width), std::uint32_t(f.height),
                      std::uint32_t(base::packed_stride(f.pixel, f.width)), 0u);
  return v;
}

void copy_rows(const std::uint8_t *from, std::size_t from_stride, std::uint8_t *to,
               std::size_t to_stride, const base::VideoFormat &f) {
  const std::size_t row = base::packed_stride(f.pixel, f.width);
  for (std::size_t y = 0; y < base::frame_rows(f); ++y)
    std::memcpy(to + y * to_stride, from + y * from_stride, row);
}

void copy_rects(const std::uint8_t *from, std::size_t from_stride, std::uint8_t *to,
                std::size_t to_stride, const base::VideoFormat &f,
                std::span<const PixelRect> rects) {
  const std::size_t pixel_bytes = base::packed_stride(f.pixel, 2) / 2; // NV12: its luma
  const std::size_t chroma_row = f.pixel == base::PixelFormat::nv12 ? std::size_t(f.height) : 0;
  const auto copy = [&](std::size_t row, std::size_t x0, std::size_t x1) {
    std::memcpy(to + row * to_stride + x0 * pixel_bytes,
                from + row * from_stride + x0 * pixel_bytes, (x1 - x0) * pixel_bytes);
  };
  for (const PixelRect &rect : rects)
    for (std::uint32_t y = rect.y0; y < rect.y1; ++y) {
      copy(y, rect.x0, rect.x1);
      if (chroma_row != 0 && y % 2 == 0) // a Cb Cr pair per luma pair, a row per two
        copy(chroma_row + y / 2, rect.x0, rect.x1);
    }
}

} // namespace camhead::renderer
