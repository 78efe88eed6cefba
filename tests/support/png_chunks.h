// Hand-made PNG files for the readers' tests: chunks with their CRC and
// zlib streams, for the damaged files that no encoder writes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <zlib.h>

namespace camhead::test {

inline std::string be32(std::uint32_t v) {
  return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

// One PNG chunk: length, type, data and CRC.
inline std::string png_chunk(const std::string &type, const std::string &data) {
  const std::string body = type + data;
  const auto crc = crc32(0, reinterpret_cast<const Bytef *>(body.data()), uInt(body.size()));
  return be32(std::uint32_t(data.size())) + body + be32(std::uint32_t(crc));
}

inline std::string zlib_compressed(const std::string &raw) {
  uLongf size = compressBound(uLong(raw.size()));
  std::string z(size, '\0');
  compress2(reinterpret_cast<Bytef *>(z.data()), &size, reinterpret_cast<const Bytef *>(raw.data()),
            uLong(raw.size()), 9);
  z.resize(size);
  return z;
}

// `png` with the CRC of every whole chunk made right, so that a damaged
// file (a size changed in IHDR, a fuzzer's finding) reaches the decoder's
// handling of what is really wrong with it rather than stopping at a CRC.
inline std::string with_crcs_fixed(std::string png) {
  for (std::size_t at = 8; at + 12 <= png.size();) {
    const std::uint32_t length = std::uint32_t(std::uint8_t(png[at])) << 24 |
                                 std::uint32_t(std::uint8_t(png[at + 1])) << 16 |
                                 std::uint32_t(std::uint8_t(png[at + 2])) << 8 |
                                 std::uint8_t(png[at + 3]);
    if (length > png.size() - at - 12)
      break; // cut short: nothing to make right
    const auto crc = crc32(0, reinterpret_cast<const Bytef *>(png.data() + at + 4), length + 4);
    png.replace(at + 8 + length, 4, be32(std::uint32_t(crc)));
    at += 12 + std::size_t(length);
  }
  return png;
}

// An 8-bit RGB PNG of `width` x `height` whose image data is `raw`
// inflated, whatever its size.
inline std::string rgb8_png(std::uint32_t width, std::uint32_t height, const std::string &raw) {
  return "\x89PNG\r\n\x1a\n" +
         png_chunk("IHDR", be32(width) + be32(height) + std::string{8, 2, 0, 0, 0}) +
         png_chunk("IDAT", zlib_compressed(raw)) + png_chunk("IEND", "");
}

} // namespace camhead::test
