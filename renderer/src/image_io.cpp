// OpenEXR through tinyexr, PNG through libpng (base/png_reader.h) and
// stb_image_write, all static or compiled into this file only, so that the
// renderer links nothing but Vulkan dynamically. Files are read into memory
// first so that every failure, including open errors, is reported the same
// way (ImageError naming the file).
#include "camhead/renderer/image_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <zlib.h>

#include "camhead/base/input_file.h"
#include "camhead/base/partial_file.h"
#include "camhead/base/png_reader.h"

#define TINYEXR_USE_MINIZ 0
#define TINYEXR_IMPLEMENTATION
#include <tinyexr.h>
#define STBI_WRITE_NO_STDIO
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

namespace camhead::renderer {
namespace {

// Far beyond any render (65536 x 2048) yet small enough that a corrupt header
// cannot make us allocate tens of gigabytes.
// 8K UHD (7680 x 4320) fits; a 16-bit RGB decode of this many pixels is
// 192 MiB beside the float image's 384, the most a file of any size can make
// the PNG reader allocate (tinyexr: 256 MiB of 16-bit RGBA).
constexpr std::size_t kMaxPixels = std::size_t(1) << 25;

[[noreturn]] void fail(const std::filesystem::path &path, const std::string &reason) {
  throw ImageError(path.string() + ": " + reason);
}

// An uncompressed float RGBA EXR of kMaxPixels is 512 MiB.
constexpr std::size_t kMaxImageFileBytes = std::size_t(1) << 30;

// Beside `path` and renamed over it when whole (base/partial_file.h): a
// write that fails half-way leaves the previous file as it was.
void write_file(const std::filesystem::path &path, const unsigned char *data, std::size_t size) {
  std::string error;
  std::optional<base::PartialFile> file = base::PartialFile::create(path, error);
  if (!file || !file->write(std::span(data, size), error) || !file->commit(true, error))
    fail(path, error);
}

std::string lower_extension(const std::filesystem::path &path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

// Double precision so that PNG encoding rounds exactly like the numpy
// reference (imageio_util.py), which works in float64.
double srgb_to_linear_d(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

double linear_to_srgb_d(double v) {
  // !(v > 0) also maps NaN to 0, so that the 8-bit conversion never sees it.
  v = !(v > 0.0) ? 0.0 : std::min(v, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

struct ExrErrorDeleter {
  void operator()(const char *msg) const { FreeEXRErrorMessage(msg); }
};
using ExrMessage = std::unique_ptr<const char, ExrErrorDeleter>;

std::string exr_reason(const char *what, const ExrMessage &msg) {
  return std::string(what) + (msg ? std::string(": ") + msg.get() : std::string());
}

struct ExrHeader {
  EXRHeader h;
  ExrHeader() { InitEXRHeader(&h); }
  ~ExrHeader() { FreeEXRHeader(&h); }
  ExrHeader(const ExrHeader &) = delete;
  ExrHeader &operator=(const ExrHeader &) = delete;
};

// tinyexr frees a failed load itself without clearing the pointers, so the
// image is released only once it has loaded.
struct ExrImage {
  EXRImage img;
  bool loaded = false;
  ExrImage() { InitEXRImage(&img); }
  ~ExrImage() {
    if (loaded)
      FreeEXRImage(&img);
  }
  ExrImage(const ExrImage &) = delete;
  ExrImage &operator=(const ExrImage &) = delete;
};

template <typename T> T load_le(const unsigned char *p) {
  T v = 0;
  for (std::size_t k = sizeof(T); k-- > 0;)
    v = T(v << 8 | T(p[k]));
  return v;
}

// tinyexr's header parser asserts on (and, without asserts, reads past) a
// "tiles" attribute that is not 9 bytes and runs strlen() over "name" and
// "type" values; such attributes are refused before it sees them.
void check_attributes(const std::filesystem::path &path, std::span<const unsigned char> bytes) {
  const auto *text = reinterpret_cast<const char *>(bytes.data());
  const auto skip_string = [&](std::size_t at) { // one past its NUL, or past the end
    return at >= bytes.size() ? bytes.size() + 1 : at + strnlen(text + at, bytes.size() - at) + 1;
  };
  std::size_t pos = 8; // magic number and version
  while (pos < bytes.size() && bytes[pos] != 0) {
    const std::size_t size_at = skip_string(skip_string(pos));
    if (size_at > bytes.size() || bytes.size() - size_at < 4)
      return; // malformed: tinyexr reports it
    const std::size_t size = load_le<std::uint32_t>(&bytes[size_at]), data = size_at + 4;
    if (size > bytes.size() - data)
      return;
    const std::string attr(text + pos);
    const bool unterminated = size > 0 && std::memchr(text + data, 0, size) == nullptr;
    if ((attr == "tiles" && size != 9) || ((attr == "name" || attr == "type") && unterminated))
      fail(path, "malformed header attribute " + attr);
    pos = data + size;
  }
}

// tinyexr trusts the tile coordinates stored in each chunk (and multiplies
// them unchecked), so a tiled file's offset table and chunk headers are
// checked here first: one level, every offset inside the file, every chunk
// at the tile its table slot names.
void check_tiles(const std::filesystem::path &path, std::span<const unsigned char> bytes,
                 const EXRHeader &h, long long w, long long hgt) {
  const long long tx = h.tile_size_x, ty = h.tile_size_y;
  if (h.tile_level_mode != TINYEXR_TILE_ONE_LEVEL || tx < 1 || ty < 1 || tx > 65536 || ty > 65536)
    fail(path, "only single-level tiled OpenEXR files with sane tile sizes are supported");
  const std::size_t nx = std::size_t((w + tx - 1) / tx), ny = std::size_t((hgt + ty - 1) / ty);
  const std::size_t table = std::size_t(h.header_len) + 8, end = table + 8 * nx * ny;
  if (end > bytes.size())
    fail(path, "truncated tile offset table");
  for (std::size_t i = 0; i < nx * ny; ++i) {
    const auto offset = load_le<std::uint64_t>(&bytes[table + 8 * i]);
    if (offset < end || offset > bytes.size() || bytes.size() - offset < 20)
      fail(path, "bad tile offset");
    const unsigned char *chunk = &bytes[std::size_t(offset)];
    if (load_le<std::uint32_t>(chunk) != i % nx || load_le<std::uint32_t>(chunk + 4) != i / nx ||
        load_le<std::uint32_t>(chunk + 8) != 0 || load_le<std::uint32_t>(chunk + 12) != 0)
      fail(path, "tile chunk does not match its table slot");
  }
}

// Refuses an image whose header says another size than the caller needs.
void check_size(const std::filesystem::path &path, long long w, long long h,
                const std::optional<ImageSize> &expected) {
  if (!expected)
    return;
  if (expected->or_smaller) {
    if (w > expected->width || h > expected->height)
      fail(path, "is " + std::to_string(w) + "x" + std::to_string(h) + ", larger than the " +
                     std::to_string(expected->width) + "x" + std::to_string(expected->height) +
                     " allowed");
  } else if (w != expected->width || h != expected->height) {
    fail(path, "is " + std::to_string(w) + "x" + std::to_string(h) + ", not the " +
                   std::to_string(expected->width) + "x" + std::to_string(expected->height) +
                   " needed");
  }
}

// The chunks a scanline image of `lines` lines has, for the codecs read.
long long scanline_blocks(int compression, long long lines) {
  const long long per_block = compression == TINYEXR_COMPRESSIONTYPE_ZIP ? 16 : 1;
  return (lines + per_block - 1) / per_block;
}

Image read_exr(const std::filesystem::path &path, std::span<const unsigned char> bytes,
               const std::optional<ImageSize> &expected) {
  EXRVersion version;
  if (ParseEXRVersionFromMemory(&version, bytes.data(), bytes.size()) != TINYEXR_SUCCESS)
    fail(path, "not an OpenEXR file");
  if (version.multipart || version.non_image)
    fail(path, "multi-part and deep OpenEXR files are not supported");
  check_attributes(path, bytes);
  ExrHeader header;
  const char *raw_err = nullptr;
  int rc = ParseEXRHeaderFromMemory(&header.h, &version, bytes.data(), bytes.size(), &raw_err);
  ExrMessage err(raw_err);
  if (rc != TINYEXR_SUCCESS)
    fail(path, exr_reason("bad OpenEXR header", err));
  const EXRBox2i &dw = header.h.data_window;
  // tinyexr does int arithmetic on the window corners; keep them far from overflow.
  constexpr int kMaxCoord = 1 << 30;
  for (const int v : {dw.min_x, dw.min_y, dw.max_x, dw.max_y})
    if (v < -kMaxCoord || v > kMaxCoord)
      fail(path, "data window out of range");
  const long long w = (long long)dw.max_x - dw.min_x + 1;
  const long long h = (long long)dw.max_y - dw.min_y + 1;
  check_size(path, w, h, expected);
  if (w < 1 || h < 1 || std::size_t(w) * std::size_t(h) > kMaxPixels)
    fail(path, "unsupported data window size");
  // tinyexr's PIZ decoder overruns its buffers on damaged files (found by
  // tests/fuzz/exr_fuzz); ZIP, camhead's and Blender's default, and the
  // simpler codecs are read.
  const int compression = header.h.compression_type;
  if (compression != TINYEXR_COMPRESSIONTYPE_NONE && compression != TINYEXR_COMPRESSIONTYPE_RLE &&
      compression != TINYEXR_COMPRESSIONTYPE_ZIPS && compression != TINYEXR_COMPRESSIONTYPE_ZIP)
    fail(path, "compression " +
                   std::string(compression == TINYEXR_COMPRESSIONTYPE_PIZ
                                   ? "PIZ"
                                   : "type " + std::to_string(compression)) +
                   " is not supported; save as ZIP (or uncompressed)");
  int idx[3] = {-1, -1, -1};
  int luma = -1;
  for (int c = 0; c < header.h.num_channels; ++c) {
    const EXRChannelInfo &ch = header.h.channels[c];
    if (ch.x_sampling != 1 || ch.y_sampling != 1)
      fail(path, std::string("subsampled channel ") + ch.name + " is not supported");
    // tinyexr reads up to 3 bytes past a damaged chunk of 32-bit integers
    // (tests/fuzz/exr_fuzz); pictures are half or float.
    if (header.h.pixel_types[c] == TINYEXR_PIXELTYPE_UINT)
      fail(path, std::string("channel ") + ch.name +
                     " holds 32-bit integers; only half and float channels are read");
    const std::string name = ch.name;
    if (name == "R" || name == "G" || name == "B")
      idx[name == "R" ? 0 : name == "G" ? 1 : 2] = c;
    else if (name == "Y")
      luma = c;
    if (header.h.pixel_types[c] == TINYEXR_PIXELTYPE_HALF)
      header.h.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
  }
  const bool rgb = idx[0] >= 0 && idx[1] >= 0 && idx[2] >= 0;
  if (!rgb && luma < 0)
    fail(path, "needs R, G and B channels or a Y channel");
  if (!rgb)
    idx[0] = idx[1] = idx[2] = luma;
  if (header.h.tiled)
    check_tiles(path, bytes, header.h, w, h);
  else if (header.h.chunk_count != 0 && header.h.chunk_count != scanline_blocks(compression, h))
    // tinyexr sizes its offset table by this attribute (a 2 KB file
    // asked for 11 GB, tests/fuzz/exr_fuzz).
    fail(path, "chunkCount is " + std::to_string(header.h.chunk_count) +
                   "; its data window needs " + std::to_string(scanline_blocks(compression, h)));
  ExrImage image;
  // tinyexr frees the channels of a failed scanline decode by this count,
  // which it only fills in on success.
  image.img.num_channels = header.h.num_channels;
  raw_err = nullptr;
  rc = LoadEXRImageFromMemory(&image.img, &header.h, bytes.data(), bytes.size(), &raw_err);
  err.reset(raw_err);
  if (rc != TINYEXR_SUCCESS)
    fail(path, exr_reason("cannot decode pixels", err));
  image.loaded = true;
  if (image.img.width != w || image.img.height != h)
    fail(path, "decoded size does not match the data window");

  Image out(int(w), int(h), 3);
  const auto put = [&](const unsigned char *const *planes, std::size_t src, int x, int y) {
    float *px = out.at(x, y);
    for (int k = 0; k < 3; ++k)
      px[k] = reinterpret_cast<const float *>(planes[idx[k]])[src]; // all requested as float
  };
  if (header.h.tiled) {
    const int tw = header.h.tile_size_x;
    const int th = header.h.tile_size_y;
    for (int t = 0; t < image.img.num_tiles; ++t) {
      const EXRTile &tile = image.img.tiles[t];
      for (int j = 0; j < tile.height && j < th; ++j) {
        for (int i = 0; i < tile.width && i < tw; ++i) {
          const long long x = (long long)tile.offset_x * tw + i;
          const long long y = (long long)tile.offset_y * th + j;
          if (x >= 0 && y >= 0 && x < w && y < h)
            put(tile.images, std::size_t(j) * std::size_t(tw) + std::size_t(i), int(x), int(y));
        }
      }
    }
  } else {
    for (int y = 0; y < int(h); ++y)
      for (int x = 0; x < int(w); ++x)
        put(image.img.images, std::size_t(y) * std::size_t(w) + std::size_t(x), x, y);
  }
  return out;
}

void write_exr(const std::filesystem::path &path, const Image &image) {
  const std::size_t n = image.pixel_count();
  // EXR viewers expect channels in alphabetical order: B, G, R.
  const std::vector<std::pair<const char *, int>> layout =
      image.channels == 1 ? std::vector<std::pair<const char *, int>>{{"Y", 0}}
                          : std::vector<std::pair<const char *, int>>{{"B", 2}, {"G", 1}, {"R", 0}};
  std::vector<std::vector<float>> planes(layout.size(), std::vector<float>(n));
  std::vector<unsigned char *> plane_ptrs;
  std::vector<EXRChannelInfo> infos(layout.size());
  for (std::size_t c = 0; c < layout.size(); ++c) {
    for (std::size_t i = 0; i < n; ++i)
      planes[c][i] = image.data[i * std::size_t(image.channels) + std::size_t(layout[c].second)];
    plane_ptrs.push_back(reinterpret_cast<unsigned char *>(planes[c].data()));
    std::memset(&infos[c], 0, sizeof(EXRChannelInfo));
    std::strncpy(infos[c].name, layout[c].first, sizeof(infos[c].name) - 1);
  }
  std::vector<int> types(layout.size(), TINYEXR_PIXELTYPE_FLOAT);

  EXRHeader header;
  InitEXRHeader(&header); // owns nothing here: every array below lives in a vector
  header.num_channels = int(layout.size());
  header.channels = infos.data();
  header.pixel_types = types.data();
  header.requested_pixel_types = types.data();
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
  EXRImage exr;
  InitEXRImage(&exr);
  exr.num_channels = int(layout.size());
  exr.images = plane_ptrs.data();
  exr.width = image.width;
  exr.height = image.height;

  unsigned char *raw_mem = nullptr;
  const char *raw_err = nullptr;
  const std::size_t size = SaveEXRImageToMemory(&exr, &header, &raw_mem, &raw_err);
  const ExrMessage err(raw_err);
  const std::unique_ptr<unsigned char, decltype(&std::free)> mem(raw_mem, &std::free);
  if (size == 0 || !mem)
    fail(path, exr_reason("cannot encode OpenEXR", err));
  write_file(path, mem.get(), size);
}

Image read_png(const std::filesystem::path &path, std::span<const unsigned char> file,
               const std::optional<ImageSize> &expected) {
  std::string error;
  const std::optional<base::PngInfo> info = base::read_png_info(file, error);
  if (!info)
    fail(path, error);
  check_size(path, info->width, info->height, expected);
  if (info->width < 1 || info->height < 1 ||
      std::size_t(info->width) * std::size_t(info->height) > kMaxPixels)
    fail(path, "unsupported image size");
  const std::size_t samples_rgb = std::size_t(info->width) * std::size_t(info->height) * 3;
  Image out;
  if (info->sixteen_bit) {
    std::vector<std::uint16_t> samples(samples_rgb);
    if (!base::decode_png_rgb(file, *info, std::span(samples), error))
      fail(path, error);
    out = Image(info->width, info->height, 3);
    for (std::size_t i = 0; i < samples.size(); ++i)
      out.data[i] = float(srgb_to_linear_d(samples[i] / 65535.0));
  } else {
    std::vector<std::uint8_t> samples(samples_rgb);
    if (!base::decode_png_rgb(file, *info, std::span(samples), error))
      fail(path, error);
    out = Image(info->width, info->height, 3);
    // 256 values: a table instead of a pow() per sample.
    std::array<float, 256> linear;
    for (std::size_t v = 0; v < linear.size(); ++v)
      linear[v] = float(srgb_to_linear_d(double(v) / 255.0));
    for (std::size_t i = 0; i < samples.size(); ++i)
      out.data[i] = linear[samples[i]];
  }
  return out;
}

void append_bytes(void *context, void *data, int size) {
  auto *out = static_cast<std::vector<unsigned char> *>(context);
  const auto *bytes = static_cast<const unsigned char *>(data);
  out->insert(out->end(), bytes, bytes + size);
}

void write_png(const std::filesystem::path &path, const Image &image) {
  std::vector<unsigned char> pixels(image.data.size());
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    // nearbyint rounds half to even, as numpy's round does.
    pixels[i] = (unsigned char)std::nearbyint(linear_to_srgb_d(image.data[i]) * 255.0);
  }
  std::vector<unsigned char> encoded;
  const int stride = image.width * image.channels;
  if (!stbi_write_png_to_func(&append_bytes, &encoded, image.width, image.height, image.channels,
                              pixels.data(), stride))
    fail(path, "cannot encode PNG");
  write_file(path, encoded.data(), encoded.size());
}

} // namespace

float srgb_to_linear(float v) {
  return float(srgb_to_linear_d(v));
}

float linear_to_srgb(float v) {
  return float(linear_to_srgb_d(v));
}

Image decode_image(std::span<const unsigned char> bytes, const std::filesystem::path &path,
                   std::optional<ImageSize> expected) {
  const std::string ext = lower_extension(path);
  if (ext == ".exr")
    return read_exr(path, bytes, expected);
  if (ext == ".png")
    return read_png(path, bytes, expected);
  fail(path, "unsupported image type (expected .exr or .png)");
}

Image read_image(const std::filesystem::path &path, std::optional<ImageSize> expected) {
  const std::string ext = lower_extension(path);
  if (ext != ".exr" && ext != ".png")
    fail(path, "unsupported image type (expected .exr or .png)");
  std::vector<unsigned char> bytes;
  std::string error;
  if (!base::read_input_file(path, kMaxImageFileBytes, bytes, error))
    fail(path, error);
  return decode_image(bytes, path, expected);
}

void write_image(const std::filesystem::path &path, const Image &image) {
  if (image.width < 1 || image.height < 1 || (image.channels != 1 && image.channels != 3) ||
      image.data.size() != image.pixel_count() * std::size_t(image.channels) ||
      image.pixel_count() > kMaxPixels)
    fail(path, "invalid image (needs a positive size, 1 or 3 channels and matching data)");
  const std::string ext = lower_extension(path);
  if (ext == ".exr")
    write_exr(path, image);
  else if (ext == ".png")
    write_png(path, image);
  else
    fail(path, "unsupported image type (expected .exr or .png)");
}

} // namespace camhead::renderer
