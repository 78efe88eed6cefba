// JPEG through stb, compiled into this file only (static symbols, so the
// PNG copies in hal/video_file and the renderer do not clash).
#include "camhead/hal/jpeg/jpeg_frame.h"

#include <climits>
#include <cstring>
#include <memory>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wtype-limits"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// Only JPEG: a camera is a device anyone may plug in, and every other
// decoder would be attack surface for nothing.
#define STBI_ONLY_JPEG
#define STBI_NO_STDIO
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#define STBI_WRITE_NO_STDIO
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

namespace camhead::hal::jpeg {
namespace {

std::string stb_reason() {
  const char *reason = stbi_failure_reason();
  return reason != nullptr ? reason : "unknown";
}

void append(void *context, void *data, int size) {
  auto *out = static_cast<std::vector<std::uint8_t> *>(context);
  const auto *bytes = static_cast<const std::uint8_t *>(data);
  out->insert(out->end(), bytes, bytes + size);
}

} // namespace

bool decode_jpeg_rgb(std::span<const std::uint8_t> jpeg, int width, int height,
                     std::span<std::uint8_t> rgb, std::string &error) {
  if (jpeg.empty() || jpeg.size() > std::size_t(INT_MAX)) {
    error = "JPEG: empty frame";
    return false;
  }
  const int length = static_cast<int>(jpeg.size());
  int w = 0, h = 0, channels = 0;
  // The header first: a frame of another size is refused before stb
  // allocates for it.
  if (!stbi_info_from_memory(jpeg.data(), length, &w, &h, &channels)) {
    error = "JPEG: not a JPEG frame (" + stb_reason() + ")";
    return false;
  }
  if (w != width || h != height) {
    error = "JPEG: the frame is " + std::to_string(w) + "x" + std::to_string(h) + ", not " +
            std::to_string(width) + "x" + std::to_string(height);
    return false;
  }
  if (rgb.size() < std::size_t(width) * std::size_t(height) * 3) {
    error = "JPEG: the buffer holds " + std::to_string(rgb.size()) + " bytes, not a " +
            std::to_string(width) + "x" + std::to_string(height) + " RGB frame";
    return false;
  }
  const std::unique_ptr<stbi_uc, decltype(&stbi_image_free)> pixels(
      stbi_load_from_memory(jpeg.data(), length, &w, &h, &channels, 3), &stbi_image_free);
  if (!pixels) {
    error = "JPEG: cannot decode (" + stb_reason() + ")";
    return false;
  }
  std::memcpy(rgb.data(), pixels.get(), std::size_t(width) * std::size_t(height) * 3);
  return true;
}

std::vector<std::uint8_t> encode_jpeg_rgb(std::span<const std::uint8_t> rgb, int width, int height,
                                          int quality) {
  std::vector<std::uint8_t> out;
  if (rgb.size() >= std::size_t(width) * std::size_t(height) * 3)
    stbi_write_jpg_to_func(append, &out, width, height, 3, rgb.data(), quality);
  return out;
}

} // namespace camhead::hal::jpeg
