// PNG decoding through base/png_reader.h (libpng); encoding through
// stb_image_write, compiled into this file only (private, static symbols, so
// the renderer's own copy in image_io.cpp does not clash). See png_frame.h.
#include "camhead/hal/video_file/png_frame.h"

#include <climits>
#include <optional>
#include <string>
#include <vector>

#include "camhead/base/png_reader.h"

#define STBI_WRITE_NO_STDIO
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

namespace camhead::hal::video_file {
namespace {

void append_bytes(void *context, void *data, int size) {
  auto *out = static_cast<std::vector<std::uint8_t> *>(context);
  const auto *bytes = static_cast<const std::uint8_t *>(data);
  out->insert(out->end(), bytes, bytes + size);
}

bool encode_png(std::span<const std::uint8_t> pixels, int width, int height, int channels,
                std::size_t stride, std::vector<std::uint8_t> &png) {
  png.clear();
  if (stride > std::size_t(INT_MAX) || pixels.size() < stride * std::size_t(height))
    return false;
  return stbi_write_png_to_func(&append_bytes, &png, width, height, channels, pixels.data(),
                                static_cast<int>(stride)) != 0;
}

} // namespace

std::optional<PngSize> png_size(std::span<const std::uint8_t> file, std::string &error) {
  const std::optional<base::PngInfo> info = base::read_png_info(file, error);
  if (!info) {
    error = "PNG: " + error;
    return std::nullopt;
  }
  return PngSize{info->width, info->height};
}

bool decode_png_rgb(std::span<const std::uint8_t> file, PngSize expected,
                    std::span<std::uint8_t> rgb, std::string &error) {
  if (base::decode_png_rgb(file, {expected.width, expected.height}, rgb, error))
    return true;
  error = "PNG: " + error;
  return false;
}

bool encode_png_rgb(std::span<const std::uint8_t> rgb, int width, int height, std::size_t stride,
                    std::vector<std::uint8_t> &png) {
  return encode_png(rgb, width, height, 3, stride, png);
}

bool encode_png_grey(std::span<const std::uint8_t> grey, int width, int height, std::size_t stride,
                     std::vector<std::uint8_t> &png) {
  return encode_png(grey, width, height, 1, stride, png);
}

} // namespace camhead::hal::video_file
