#include "camhead/base/video_format.h"

#include <array>
#include <utility>

namespace camhead::base {
namespace {

constexpr std::array<std::pair<PixelFormat, std::string_view>, 5> kNames = {{
    {PixelFormat::yuyv, "yuyv"},
    {PixelFormat::nv12, "nv12"},
    {PixelFormat::rgb24, "rgb24"},
    {PixelFormat::bgr24, "bgr24"},
    {PixelFormat::xrgb8888, "xrgb8888"},
}};

} // namespace

bool is_yuv(PixelFormat format) {
  return format == PixelFormat::yuyv || format == PixelFormat::nv12;
}

std::size_t packed_stride(PixelFormat format, int width) {
  const auto w = static_cast<std::size_t>(width > 0 ? width : 0);
  switch (format) {
  case PixelFormat::yuyv:
    return 2 * w;
  case PixelFormat::nv12:
    return w;
  case PixelFormat::rgb24:
  case PixelFormat::bgr24:
    return 3 * w;
  case PixelFormat::xrgb8888:
    return 4 * w;
  }
  return 0;
}

std::size_t row_bytes(const VideoFormat &format) {
  return format.stride > 0 ? static_cast<std::size_t>(format.stride)
                           : packed_stride(format.pixel, format.width);
}

std::size_t frame_rows(const VideoFormat &format) {
  const std::size_t rows = static_cast<std::size_t>(format.height > 0 ? format.height : 0);
  // NV12's chroma plane: half the rows at the same stride.
  return format.pixel == PixelFormat::nv12 ? rows + (rows + 1) / 2 : rows;
}

std::size_t frame_bytes(const VideoFormat &format) {
  return row_bytes(format) * frame_rows(format);
}

std::string check_video_format(const VideoFormat &format) {
  if (format.width <= 0 || format.height <= 0)
    return "size " + std::to_string(format.width) + "x" + std::to_string(format.height) +
           " is empty";
  // 16384 covers 16K video and keeps every byte count far inside size_t.
  if (format.width > 16384 || format.height > 16384)
    return "size " + std::to_string(format.width) + "x" + std::to_string(format.height) +
           " is over 16384 pixels a side";
  if (is_yuv(format.pixel) && format.width % 2 != 0)
    return std::string(pixel_format_name(format.pixel)) + " needs an even width, not " +
           std::to_string(format.width);
  if (format.pixel == PixelFormat::nv12 && format.height % 2 != 0)
    return "nv12 needs an even height, not " + std::to_string(format.height);
  if (format.stride != 0 &&
      static_cast<std::size_t>(format.stride) < packed_stride(format.pixel, format.width))
    return "stride " + std::to_string(format.stride) + " is shorter than a row of " +
           std::to_string(packed_stride(format.pixel, format.width)) + " bytes";
  return {};
}

std::string_view pixel_format_name(PixelFormat format) {
  for (const auto &[value, name] : kNames)
    if (value == format)
      return name;
  return "?";
}

std::optional<PixelFormat> parse_pixel_format(std::string_view name) {
  for (const auto &[value, known] : kNames)
    if (known == name)
      return value;
  return std::nullopt;
}

std::string_view color_matrix_name(ColorMatrix matrix) {
  return matrix == ColorMatrix::bt601 ? "bt601" : "bt709";
}

std::string_view color_range_name(ColorRange range) {
  return range == ColorRange::limited ? "limited" : "full";
}

std::string describe(const VideoFormat &format) {
  std::string text = std::to_string(format.width) + "x" + std::to_string(format.height) + " " +
                     std::string(pixel_format_name(format.pixel));
  if (is_yuv(format.pixel))
    text += " " + std::string(color_matrix_name(format.matrix)) + " " +
            std::string(color_range_name(format.range));
  return text;
}

} // namespace camhead::base
