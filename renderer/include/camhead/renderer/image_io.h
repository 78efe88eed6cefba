// Image files: OpenEXR (linear) through tinyexr and PNG (8-bit sRGB) through
// stb, both header-only so that the renderer needs no shared libraries.
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>

#include "camhead/renderer/image.h"

namespace camhead::renderer {

class ImageError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

struct ImageSize {
  int width = 0;
  int height = 0;
  bool or_smaller = false; // a limit on each side rather than the size itself
};

// EXR: RGB (or Y) channels as linear float. PNG: 8/16-bit sRGB decoded to
// linear. Returns a 3-channel image. Throws ImageError naming the file.
// With `expected`, an image of another size (or, or_smaller, a larger one)
// is refused from its header, before anything is decoded: a small file can
// claim a vast image.
// Files over 1 GiB are refused unread.
[[nodiscard]] Image read_image(const std::filesystem::path &path,
                               std::optional<ImageSize> expected = std::nullopt);

// The same from the file's bytes; `path` picks the format by its extension
// and names the file in errors.
[[nodiscard]] Image decode_image(std::span<const unsigned char> bytes,
                                 const std::filesystem::path &path,
                                 std::optional<ImageSize> expected = std::nullopt);

// Chosen by extension: .exr writes linear float32 (ZIP); .png writes 8-bit
// sRGB, clipped to [0, 1] and rounded. 1-channel images are written as grey.
void write_image(const std::filesystem::path &path, const Image &image);

[[nodiscard]] float srgb_to_linear(float v);
[[nodiscard]] float linear_to_srgb(float v);

} // namespace camhead::renderer
