// PNG frames: the whole file is read into memory first, the size is taken
// from the header and checked before anything is decoded (a few bytes can
// claim a 100000 x 100000 image), and decoding (libpng, base/png_reader.h)
// gives 8-bit RGB whatever the file holds (palette, grey, alpha and 16-bit
// are converted). Encoding (stb_image_write) writes 8-bit RGB. Errors are
// values: the file camera calls these at play time, where nothing may
// throw. Any thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace camhead::hal::video_file {

// A 16384 x 16384 RGB PNG that does not compress at all is about 805 MB
// (the most base::read_input_file reads of a frame).
inline constexpr std::size_t kMaxPngFileBytes = std::size_t(1) << 30;

struct PngSize {
  int width = 0;
  int height = 0;
  bool operator==(const PngSize &) const = default;
};

// The size the PNG header states; empty with `error` if it is not a PNG.
[[nodiscard]] std::optional<PngSize> png_size(std::span<const std::uint8_t> file,
                                              std::string &error);

// Decodes into `rgb`, width * 3 bytes a row, no padding, which must be
// exactly the size of `expected` (what png_size said). False with `error`
// when the file is damaged (base::decode_png_rgb) or is another size.
[[nodiscard]] bool decode_png_rgb(std::span<const std::uint8_t> file, PngSize expected,
                                  std::span<std::uint8_t> rgb, std::string &error);

// Encodes 8-bit RGB rows of `stride` bytes into `png` (replaced). False only
// when stb cannot (out of memory).
[[nodiscard]] bool encode_png_rgb(std::span<const std::uint8_t> rgb, int width, int height,
                                  std::size_t stride, std::vector<std::uint8_t> &png);
// The same for 8-bit grey rows (a luma plane).
[[nodiscard]] bool encode_png_grey(std::span<const std::uint8_t> grey, int width, int height,
                                   std::size_t stride, std::vector<std::uint8_t> &png);

} // namespace camhead::hal::video_file
