#include "camhead/base/png_reader.h"

#include <bit>
#include <cctype>
#include <csetjmp>
#include <cstdio>
#include <cstring>

#include <png.h>

namespace camhead::base {
namespace {

// The file as libpng reads it, and the message of what ended the read.
// libpng's build limits stay: a million pixels a side, and 8 MB for an
// ancillary chunk held in memory (text, ICC profiles), 1000 of them.
struct Source {
  std::span<const std::uint8_t> file;
  std::size_t at = 0;
  char error[192] = {};
};

void read_from_memory(png_structp png, png_bytep out, std::size_t n) {
  Source &source = *static_cast<Source *>(png_get_io_ptr(png));
  if (n > source.file.size() - source.at)
    png_error(png, "the file ends inside a chunk, or before IEND");
  std::memcpy(out, source.file.data() + source.at, n);
  source.at += n;
}

[[noreturn]] void stop_on_error(png_structp png, png_const_charp message) {
  Source &source = *static_cast<Source *>(png_get_error_ptr(png));
  // "Not a PNG file" reads as "not a readable PNG: not a PNG file"; "IDAT:
  // CRC error" keeps its chunk's name.
  const bool sentence = message[0] != '\0' && std::islower(static_cast<unsigned char>(message[1]));
  std::snprintf(source.error, sizeof source.error, "not a readable PNG: %c%s",
                sentence ? std::tolower(static_cast<unsigned char>(message[0])) : message[0],
                message[0] != '\0' ? message + 1 : "");
  png_longjmp(png, 1);
}

// The chunks of a PNG `file`, walked before libpng reads any: libpng
// allocates some ancillary chunks at the length they claim before it reads
// a byte of them (1.6.39's sPLT: 1.9 GB for a 126-byte file), so a chunk that
// runs past the end of the file is refused here, and no chunk can cost more
// memory than the file holds. True with the bytes of image data (IDAT
// chunks) when every chunk up to IEND is whole; else false with `error`.
bool walk_chunks(std::span<const std::uint8_t> file, std::uint64_t &image_data,
                 char (&error)[192]) {
  image_data = 0;
  for (std::size_t at = 8;;) {
    if (file.size() - at < 12) {
      std::snprintf(error, sizeof error, "not a readable PNG: the file ends before IEND");
      return false;
    }
    const std::size_t length = std::size_t(file[at]) << 24 | std::size_t(file[at + 1]) << 16 |
                               std::size_t(file[at + 2]) << 8 | file[at + 3];
    char name[5] = {};
    for (int i = 0; i < 4; ++i) {
      const auto c = static_cast<unsigned char>(file[at + 4 + std::size_t(i)]);
      name[i] = std::isalpha(c) ? char(c) : '?';
    }
    if (length > file.size() - at - 12) {
      std::snprintf(error, sizeof error,
                    "not a readable PNG: the file ends inside its %s chunk, which claims %zu "
                    "bytes",
                    name, length);
      return false;
    }
    if (std::memcmp(name, "IDAT", 4) == 0)
      image_data += length;
    if (std::memcmp(name, "IEND", 4) == 0)
      return true;
    at += 12 + length;
  }
}

// Deflate expands a byte to at most 1032 (a 258-byte match in 2 bits); a
// block header and the zlib frame add a few.
constexpr std::uint64_t kMaxInflation = 1032;
constexpr std::uint64_t kInflationSlack = 1024;

// A damaged ancillary chunk (text, colour metadata) is skipped: the image
// does not depend on it.
void skip_warning(png_structp, png_const_charp) {}

// Where the rows go: nowhere (the header alone) or `bytes` at `rows`, 8 or
// 16 bits a sample, for an image of `width` x `height`.
struct Target {
  bool header_only = true;
  int width = 0, height = 0;
  std::uint8_t *rows = nullptr;
  std::size_t bytes = 0;
  bool sixteen = false;
};

// One read of `source` into `target`. libpng reports errors by longjmp to
// the setjmp below; no object with a destructor lives in this frame, so the
// jump skips nothing. The caller's buffer is written row by row.
bool read(Source &source, const Target &target, PngInfo &info) {
  // Not a PNG at all: libpng's own words ("Not a PNG file").
  const bool signed_png = source.file.size() >= 8 && png_sig_cmp(source.file.data(), 0, 8) == 0;
  std::uint64_t data_bytes = 0;
  if (signed_png && !walk_chunks(source.file, data_bytes, source.error))
    return false;
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, &source, &stop_on_error, &skip_warning);
  png_infop header = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (header == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::snprintf(source.error, sizeof source.error, "cannot start libpng: out of memory");
    return false;
  }
  if (setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_read_struct(&png, &header, nullptr);
    return false;
  }
  png_set_read_fn(png, &source, &read_from_memory);
#if defined(FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION)
  // Mutated bytes seldom keep their CRCs right: the fuzzers (tests/fuzz)
  // would stop at the checks and never reach what lies behind them.
  png_set_crc_action(png, PNG_CRC_QUIET_USE, PNG_CRC_QUIET_USE);
#endif
  png_read_info(png, header);
  const png_uint_32 width = png_get_image_width(png, header);
  const png_uint_32 height = png_get_image_height(png, header);
  info = {int(width), int(height), png_get_bit_depth(png, header) == 16};
  // A few bytes can claim a vast image. Image data that cannot inflate to
  // the pixels claimed is refused now, before the caller allocates for them.
  const std::uint64_t pixel_bytes =
      (std::uint64_t(width) * height * png_get_bit_depth(png, header) *
           png_get_channels(png, header) +
       7) /
      8;
  if (pixel_bytes > data_bytes * kMaxInflation + kInflationSlack) {
    std::snprintf(source.error, sizeof source.error,
                  "not a readable PNG: its %llu bytes of image data cannot hold the %ux%u "
                  "image its header states",
                  static_cast<unsigned long long>(data_bytes), width, height);
    png_destroy_read_struct(&png, &header, nullptr);
    return false;
  }
  if (!target.header_only) {
    const std::size_t sample_bytes = target.sixteen ? 2 : 1;
    if (info.width != target.width || info.height != target.height ||
        std::size_t(target.width) * std::size_t(target.height) * 3 * sample_bytes != target.bytes) {
      std::snprintf(source.error, sizeof source.error, "is %ux%u, not the %dx%d expected", width,
                    height, target.width, target.height);
      png_destroy_read_struct(&png, &header, nullptr);
      return false;
    }
    png_set_expand(png); // a palette to RGB, grey below 8 bits to 8, tRNS to alpha
    png_set_gray_to_rgb(png);
    png_set_strip_alpha(png);
    if (target.sixteen) {
      png_set_expand_16(png);
      if constexpr (std::endian::native == std::endian::little)
        png_set_swap(png);
    } else {
      png_set_strip_16(png);
    }
    const int passes = png_set_interlace_handling(png);
    png_read_update_info(png, header);
    // The transforms make rows of 3 samples a pixel, as checked above.
    const std::size_t row_bytes = png_get_rowbytes(png, header);
    // Image data past the last row ("Too much image data", found as the
    // last row is read) is an error, not the warning libpng makes it by
    // default: the file is damaged, or made to cost inflating.
    png_set_benign_errors(png, 0);
    // An interlaced image's passes fill in the rows of the passes before.
    for (int pass = 0; pass < passes; ++pass)
      for (png_uint_32 y = 0; y < height; ++y)
        png_read_row(png, target.rows + y * row_bytes, nullptr);
    // The chunks after the image, up to IEND: damaged critical ones and a
    // missing IEND are errors, ancillary ones are skipped as before.
    png_set_benign_errors(png, 1);
    png_read_end(png, nullptr);
  }
  png_destroy_read_struct(&png, &header, nullptr);
  return true;
}

bool decode(std::span<const std::uint8_t> file, const Target &target, std::string &error) {
  Source source{file};
  PngInfo info;
  if (read(source, target, info))
    return true;
  error = source.error;
  return false;
}

} // namespace

std::optional<PngInfo> read_png_info(std::span<const std::uint8_t> file, std::string &error) {
  Source source{file};
  PngInfo info;
  if (read(source, {}, info))
    return info;
  error = source.error;
  return std::nullopt;
}

bool decode_png_rgb(std::span<const std::uint8_t> file, const PngInfo &size,
                    std::span<std::uint8_t> rgb, std::string &error) {
  return decode(file, {false, size.width, size.height, rgb.data(), rgb.size(), false}, error);
}

bool decode_png_rgb(std::span<const std::uint8_t> file, const PngInfo &size,
                    std::span<std::uint16_t> rgb, std::string &error) {
  return decode(file,
                {false, size.width, size.height, reinterpret_cast<std::uint8_t *>(rgb.data()),
                 rgb.size_bytes(), true},
                error);
}

} // namespace camhead::base
