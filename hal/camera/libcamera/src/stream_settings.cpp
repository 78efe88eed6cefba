// See stream_settings.h.
#include "stream_settings.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <utility>

namespace camhead::hal::camera::libcamera_settings {
namespace {

struct Known {
  base::PixelFormat camhead;
  std::uint32_t fourcc;
  const char *name; // libcamera's, formats.yaml
};

constexpr std::array<Known, 4> kFormats = {{
    {base::PixelFormat::yuyv, kYuyv, "YUYV"},
    {base::PixelFormat::nv12, kNv12, "NV12"},
    {base::PixelFormat::bgr24, kRgb888, "RGB888"},
    {base::PixelFormat::rgb24, kBgr888, "BGR888"},
}};

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

} // namespace

std::optional<std::uint32_t> libcamera_fourcc(base::PixelFormat format) {
  for (const Known &known : kFormats)
    if (known.camhead == format)
      return known.fourcc;
  return std::nullopt;
}

std::optional<base::PixelFormat> camhead_format(std::uint32_t code) {
  for (const Known &known : kFormats)
    if (known.fourcc == code)
      return known.camhead;
  return std::nullopt;
}

std::string libcamera_format_name(std::uint32_t code) {
  for (const Known &known : kFormats)
    if (known.fourcc == code)
      return known.name;
  std::string chars;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((code >> (8 * i)) & 0xff);
    if (c < 0x20 || c > 0x7e) {
      char hex[16];
      std::snprintf(hex, sizeof hex, "0x%08x", code);
      return hex;
    }
    chars += c;
  }
  // DRM pads short names with spaces ("R8  ").
  while (!chars.empty() && chars.back() == ' ')
    chars.pop_back();
  return chars;
}

std::string describe(const StreamShape &shape) {
  const std::optional<base::PixelFormat> ours = camhead_format(shape.fourcc);
  return size_text(shape.width, shape.height) + " " + libcamera_format_name(shape.fourcc) +
         (ours ? " (camhead " + std::string(base::pixel_format_name(*ours)) + ")"
               : std::string(" (no camhead format)"));
}

std::string camera_label(const std::string &id, const std::string &model) {
  return model.empty() ? "(" + id + ")" : "'" + model + "' (" + id + ")";
}

std::string adjusted_message(const std::string &camera, const StreamShape &asked,
                             const StreamShape &answered) {
  std::string advice;
  if (answered.fourcc != asked.fourcc)
    advice = "choose a format the camera offers";
  if (answered.width != asked.width || answered.height != asked.height)
    advice += std::string(advice.empty() ? "" : " and ") + "choose a size it gives unchanged (" +
              size_text(answered.width, answered.height) + " here)";
  return "libcamera camera " + camera + ": asked " + describe(asked) + ", the camera gives " +
         describe(answered) + "; " + advice;
}

std::string check_options(const LibcameraCameraOptions &options) {
  if (!libcamera_fourcc(options.format))
    return "format: " + std::string(base::pixel_format_name(options.format)) +
           " is a display format; a camera gives yuyv, nv12, rgb24 or bgr24";
  const base::VideoFormat wanted{options.format, options.width, options.height};
  if (std::string reason = base::check_video_format(wanted); !reason.empty())
    return "format: " + reason;
  if (options.buffers < 2 || options.buffers > 8)
    return "buffers: " + std::to_string(options.buffers) + " is not 2 to 8";
  return {};
}

void apply_colour(base::VideoFormat &format, const std::optional<StreamColour> &colour) {
  if (!base::is_yuv(format.pixel))
    return;
  if (!colour || colour->encoding == YcbcrEncoding::none) {
    format.matrix = format.height <= 576 ? base::ColorMatrix::bt601 : base::ColorMatrix::bt709;
    format.range = base::ColorRange::limited;
    return;
  }
  format.matrix = colour->encoding == YcbcrEncoding::rec601 ? base::ColorMatrix::bt601
                                                            : base::ColorMatrix::bt709;
  format.range = colour->full_range ? base::ColorRange::full : base::ColorRange::limited;
}

std::optional<FrameRegion> frame_region(const std::vector<Plane> &planes,
                                        const base::VideoFormat &format, std::string &error) {
  const std::size_t luma = base::row_bytes(format) * static_cast<std::size_t>(format.height);
  const std::size_t total = base::frame_bytes(format);
  // NV12 is two planes (luma, chroma) to libcamera; every other format one.
  const std::size_t expected = format.pixel == base::PixelFormat::nv12 ? 2 : 1;
  if (planes.size() != expected) {
    error = "the buffer has " + std::to_string(planes.size()) + " planes, not " +
            std::to_string(expected);
    return std::nullopt;
  }
  const Plane &first = planes.front();
  if (first.fd < 0) {
    error = "the buffer's first plane has no dmabuf";
    return std::nullopt;
  }
  if (planes.size() == 2) {
    const Plane &chroma = planes[1];
    // camhead reads NV12 as one piece, chroma right after luma at the same
    // stride (video_format.h): an NV12M layout in two dmabufs is not that.
    if (chroma.fd != first.fd || chroma.offset != first.offset + luma) {
      error = "NV12 chroma is not right after the luma in the same buffer (offset " +
              std::to_string(chroma.offset) + ", luma ends at " +
              std::to_string(first.offset + luma) + ")";
      return std::nullopt;
    }
    if (first.length < luma || chroma.length < total - luma) {
      error = "the planes hold " + std::to_string(first.length) + " + " +
              std::to_string(chroma.length) + " bytes, a frame needs " + std::to_string(luma) +
              " + " + std::to_string(total - luma);
      return std::nullopt;
    }
  } else if (first.length < total) {
    error = "the buffer holds " + std::to_string(first.length) + " bytes, a frame needs " +
            std::to_string(total);
    return std::nullopt;
  }
  std::size_t end = 0;
  for (const Plane &plane : planes)
    end = std::max(end, plane.offset + plane.length);
  return FrameRegion{first.fd, end, first.offset};
}

} // namespace camhead::hal::camera::libcamera_settings
