// Video frame formats as cameras deliver them and outputs take them: the
// plain description that hal/ (capture, output) and the renderer (conversion
// to and from linear light) share.
//
// Layouts (stride = bytes per row of the first plane, rows top to bottom):
//   yuyv      Y0 Cb Y1 Cr per pixel pair, 4:2:2 (V4L2_PIX_FMT_YUYV)
//   nv12      Y plane, then interleaved Cb Cr plane at half width and height,
//             4:2:0 with the same stride (V4L2_PIX_FMT_NV12)
//   rgb24     R G B bytes (V4L2_PIX_FMT_RGB24)
//   bgr24     B G R bytes (V4L2_PIX_FMT_BGR24, OpenCV's order)
//   xrgb8888  B G R X bytes, one little-endian 32-bit word 0xXXRRGGBB per
//             pixel (DRM_FORMAT_XRGB8888, what a display scans out)
// Chroma sits with the left (and upper) luma sample of its pair (MPEG-2 /
// H.264 default siting, type 0 horizontally).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace camhead::base {

enum class PixelFormat { yuyv, nv12, rgb24, bgr24, xrgb8888 };

// Y'CbCr coefficients; unused for the RGB formats.
enum class ColorMatrix { bt601, bt709 };
// Limited ("TV", Y' 16-235, Cb Cr 16-240) or full (0-255) code range.
enum class ColorRange { limited, full };

struct VideoFormat {
  PixelFormat pixel = PixelFormat::yuyv;
  int width = 0;
  int height = 0;
  // Bytes per row of the first plane; 0 = packed (the minimum).
  int stride = 0;
  ColorMatrix matrix = ColorMatrix::bt709;
  ColorRange range = ColorRange::limited;

  bool operator==(const VideoFormat &) const = default;
};

[[nodiscard]] bool is_yuv(PixelFormat format);

// Bytes per row without padding.
[[nodiscard]] std::size_t packed_stride(PixelFormat format, int width);
// The stride in effect: `stride`, or the packed one when it is 0.
[[nodiscard]] std::size_t row_bytes(const VideoFormat &format);
// Bytes of a whole frame, every plane.
// Rows of every plane, each row_bytes() long: the height, then NV12's
// chroma rows.
[[nodiscard]] std::size_t frame_rows(const VideoFormat &format);
[[nodiscard]] std::size_t frame_bytes(const VideoFormat &format);

// Why `format` cannot describe a frame (empty size, odd width for 4:2:2, odd
// height for 4:2:0, a stride smaller than a row), or empty when it can.
[[nodiscard]] std::string check_video_format(const VideoFormat &format);

// "yuyv", "nv12", ... as board files and messages spell them.
[[nodiscard]] std::string_view pixel_format_name(PixelFormat format);
[[nodiscard]] std::optional<PixelFormat> parse_pixel_format(std::string_view name);
[[nodiscard]] std::string_view color_matrix_name(ColorMatrix matrix);
[[nodiscard]] std::string_view color_range_name(ColorRange range);
// "720x576 yuyv bt709 limited" for status lines and errors.
[[nodiscard]] std::string describe(const VideoFormat &format);

} // namespace camhead::base
