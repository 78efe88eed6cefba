// PNG decoding for both readers of PNG files, the renderer's images and the
// file camera's frames, through libpng (linked statically, so the renderer
// still needs no shared library beyond Vulkan). libpng inflates the image
// data a row at a time into the caller's buffer, and every chunk's CRC is
// checked. The chunks are walked first, so that none that runs past the end
// of the file reaches libpng: a file cannot make it allocate more than the
// rows its header states and the chunks it holds, whatever they claim.
// The caller reads the header first (read_png_info) and checks the size it
// states before it allocates. Errors are values: the file camera decodes at
// play time, where nothing may throw. Any thread; libpng's state lives in
// each call.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace camhead::base {

struct PngInfo {
  int width = 0;
  int height = 0;
  bool sixteen_bit = false; // 16 bits a sample; else 8 or fewer
};

// What the header of `file` states. Empty with `error` ("not a readable
// PNG: ...") when it is not a PNG or its header is damaged.
[[nodiscard]] std::optional<PngInfo> read_png_info(std::span<const std::uint8_t> file,
                                                   std::string &error);

// Decodes `file`, whose header states `size` (what read_png_info said, or
// what the caller needs), into RGB rows without padding: a palette
// expanded, grey repeated into R, G and B, alpha dropped, the samples as
// stored (no gamma applied). `rgb` holds exactly width x height x 3
// samples. 8-bit samples take a 16-bit file's high bytes; 16-bit samples
// (native byte order) take an 8-bit file's times 257. False with `error`
// ("not a readable PNG: ...") when anything up to the IEND chunk is damaged:
// a CRC, the image data (too little of it, or more than the image), a chunk
// cut short; or ("is WxH, not the WxH expected") when the header states
// another size, or `rgb` does not hold it.
[[nodiscard]] bool decode_png_rgb(std::span<const std::uint8_t> file, const PngInfo &size,
                                  std::span<std::uint8_t> rgb, std::string &error);
[[nodiscard]] bool decode_png_rgb(std::span<const std::uint8_t> file, const PngInfo &size,
                                  std::span<std::uint16_t> rgb, std::string &error);

} // namespace camhead::base
