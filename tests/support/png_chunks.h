// Hand-made PNG files for the readers' tests: chunks with their CRC and
// zlib streams, for the damaged files that no encoder writes.
#pragma once

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

// An 8-bit RGB PNG of `width` x `height` whose image data is `raw`
// inflated, whatever its size.
inline std::string rgb8_png(std::uint32_t width, std::uint32_t height, const std::string &raw) {
  return "\x89PNG\r\n\x1a\n" +
         png_chunk("IHDR", be32(width) + be32(height) + std::string{8, 2, 0, 0, 0}) +
         png_chunk("IDAT", zlib_compressed(raw)) + png_chunk("IEND", "");
}

} // namespace camhead::test
