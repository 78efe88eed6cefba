#include "camhead/base/png_guard.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstring>

#include <zlib.h>

namespace camhead::base {
namespace {

// The big-endian length of the chunk at `at` (its type follows).
std::size_t chunk_length(std::span<const unsigned char> bytes, std::size_t at) {
  return std::size_t(bytes[at]) << 24 | std::size_t(bytes[at + 1]) << 16 |
         std::size_t(bytes[at + 2]) << 8 | bytes[at + 3];
}

bool is_type(std::span<const unsigned char> bytes, std::size_t at, const char *type) {
  return std::memcmp(&bytes[at + 4], type, 4) == 0;
}

} // namespace

std::optional<std::vector<unsigned char>> png_chunks_checked(std::span<const unsigned char> file,
                                                             std::string &error) {
  if (file.size() < 8 || std::memcmp(file.data(), "\x89PNG\r\n\x1a\n", 8) != 0) {
    error = "not a readable PNG: no PNG signature";
    return std::nullopt;
  }
  std::vector<unsigned char> out(file.begin(), file.begin() + 8);
  for (std::size_t at = 8;;) {
    if (at + 12 > file.size()) {
      error = "not a readable PNG: ends inside a chunk, or without IEND";
      return std::nullopt;
    }
    const std::size_t length = chunk_length(file, at);
    if (length > file.size() - at - 12) {
      error = "not a readable PNG: a chunk claims " + std::to_string(length) +
              " bytes, more than the file has";
      return std::nullopt;
    }
    if (length != 0 || !is_type(file, at, "IDAT"))
      out.insert(out.end(), file.begin() + std::ptrdiff_t(at),
                 file.begin() + std::ptrdiff_t(at + 12 + length));
    if (is_type(file, at, "IEND"))
      return out;
    at += 12 + length;
  }
}

bool png_inflates_within_header(std::span<const unsigned char> png, std::string &error) {
  std::vector<unsigned char> idat;
  std::uint64_t width = 0, height = 0, bits_per_pixel = 0;
  bool interlaced = false;
  for (std::size_t at = 8; !is_type(png, at, "IEND");) {
    const std::size_t length = chunk_length(png, at);
    const unsigned char *data = &png[at + 8];
    if (is_type(png, at, "IHDR") && length >= 13) {
      width = std::uint64_t(data[0]) << 24 | data[1] << 16 | data[2] << 8 | data[3];
      height = std::uint64_t(data[4]) << 24 | data[5] << 16 | data[6] << 8 | data[7];
      constexpr int kChannels[7] = {1, 0, 3, 1, 2, 0, 4}; // by colour type
      const int channels = data[9] < 7 ? kChannels[data[9]] : 0;
      bits_per_pixel = std::uint64_t(channels) * data[8];
      interlaced = data[12] != 0;
    } else if (is_type(png, at, "IDAT")) {
      idat.insert(idat.end(), data, data + length);
    }
    at += 12 + length;
  }
  if (bits_per_pixel == 0)
    return true; // no usable header: the decoder says what is wrong
  // A filter byte per row and the rows' bytes; interlacing adds at most a
  // filter byte per row of each of its seven passes, and a byte's rounding.
  const std::uint64_t row = (width * bits_per_pixel + 7) / 8;
  const std::uint64_t most = height * (1 + row) + (interlaced ? 7 * (height + 1) * 2 : 0) + 1024;
  z_stream z{};
  if (inflateInit(&z) != Z_OK) {
    error = "cannot start zlib";
    return false;
  }
  z.next_in = idat.data();
  z.avail_in = uInt(std::min<std::size_t>(idat.size(), UINT_MAX));
  std::vector<unsigned char> scratch(64 * 1024);
  int rc = Z_OK;
  while (rc == Z_OK) {
    z.next_out = scratch.data();
    z.avail_out = uInt(scratch.size());
    rc = inflate(&z, Z_NO_FLUSH);
    if (z.total_out > most) {
      inflateEnd(&z);
      error = "its image data inflates past the " + std::to_string(width) + "x" +
              std::to_string(height) + " image its header describes";
      return false;
    }
    if (rc == Z_BUF_ERROR && z.avail_in == 0)
      break; // the stream ends early: the decoder says so
  }
  inflateEnd(&z);
  return true;
}

} // namespace camhead::base
