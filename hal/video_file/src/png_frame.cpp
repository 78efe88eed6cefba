// PNG through stb, compiled into this file only (private, static symbols, so
// the renderer's own copy in image_io.cpp does not clash). See png_frame.h.
#include "camhead/hal/video_file/png_frame.h"

#include <climits>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

#include "camhead/base/png_guard.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wtype-limits"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#if !defined(__clang__) // GCC only; clang rejects the unknown group
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// Only PNG: frames come from files anyone may hand us, and every other
// decoder would be attack surface for nothing.
#define STBI_ONLY_PNG
#define STBI_NO_STDIO
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#define STBI_WRITE_NO_STDIO
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

namespace camhead::hal::video_file {
namespace {

std::string stb_reason() {
  const char *reason = stbi_failure_reason();
  return reason != nullptr ? reason : "unknown error";
}

void append_bytes(void *context, void *data, int size) {
  auto *out = static_cast<std::vector<std::uint8_t> *>(context);
  const auto *bytes = static_cast<const std::uint8_t *>(data);
  out->insert(out->end(), bytes, bytes + size);
}

} // namespace

std::optional<PngSize> png_size(std::span<const std::uint8_t> file, std::string &error) {
  int width = 0, height = 0, channels = 0;
  if (file.size() > std::size_t(INT_MAX) ||
      !stbi_info_from_memory(file.data(), static_cast<int>(file.size()), &width, &height,
                             &channels)) {
    error = "PNG: not a readable PNG (" + stb_reason() + ")";
    return std::nullopt;
  }
  return PngSize{width, height};
}

bool decode_png_rgb(std::span<const std::uint8_t> file, PngSize expected,
                    std::span<std::uint8_t> rgb, std::string &error) {
  const std::optional<std::vector<std::uint8_t>> checked = base::png_chunks_checked(file, error);
  if (!checked || !base::png_inflates_within_header(*checked, error)) {
    error = "PNG: " + error;
    return false;
  }
  int width = 0, height = 0, channels = 0;
  const std::unique_ptr<stbi_uc, decltype(&stbi_image_free)> pixels(
      checked->size() > std::size_t(INT_MAX)
          ? nullptr
          : stbi_load_from_memory(checked->data(), static_cast<int>(checked->size()), &width,
                                  &height, &channels, 3),
      &stbi_image_free);
  if (!pixels) {
    error = "PNG: cannot decode (" + stb_reason() + ")";
    return false;
  }
  const std::size_t bytes = std::size_t(width) * std::size_t(height) * 3;
  if (PngSize{width, height} != expected || bytes != rgb.size()) {
    error = "PNG: decodes to " + std::to_string(width) + "x" + std::to_string(height) +
            ", not the " + std::to_string(expected.width) + "x" + std::to_string(expected.height) +
            " its header states";
    return false;
  }
  std::memcpy(rgb.data(), pixels.get(), bytes);
  return true;
}

bool encode_png_rgb(std::span<const std::uint8_t> rgb, int width, int height, std::size_t stride,
                    std::vector<std::uint8_t> &png) {
  png.clear();
  if (stride > std::size_t(INT_MAX) || rgb.size() < stride * std::size_t(height))
    return false;
  return stbi_write_png_to_func(&append_bytes, &png, width, height, 3, rgb.data(),
                                static_cast<int>(stride)) != 0;
}

} // namespace camhead::hal::video_file
