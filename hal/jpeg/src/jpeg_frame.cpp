// JPEG frames decoded by libjpeg-turbo's TurboJPEG, opened at run time;
// encoded (for tests and simulated devices) by stb_image_write, compiled into
// this file only (static symbols, so the PNG writers elsewhere do not clash).
#include "camhead/hal/jpeg/jpeg_frame.h"

#include <climits>
#include <memory>

#include <dlfcn.h>
#include <turbojpeg.h> // the API's types only: the library is opened, not linked

#define STBI_WRITE_NO_STDIO
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

namespace camhead::hal::jpeg {

// The TurboJPEG functions the decoder calls, from libturbojpeg.so.0 (the
// soname of Debian 12's libturbojpeg0, libjpeg-turbo 2.1), and one
// decompressor kept for the stream's life.
struct JpegDecoder::Turbo {
  void *library = nullptr;
  decltype(&tjInitDecompress) init = nullptr;
  decltype(&tjDecompressHeader3) header = nullptr;
  decltype(&tjDecompress2) decompress = nullptr;
  decltype(&tjGetErrorStr2) error_text = nullptr;
  decltype(&tjDestroy) destroy = nullptr;
  tjhandle handle = nullptr;

  ~Turbo() {
    if (handle != nullptr)
      destroy(handle);
    if (library != nullptr)
      dlclose(library);
  }
  [[nodiscard]] std::string reason() const { return error_text(handle); }
};

namespace {

template <typename F> bool resolve(void *library, const char *symbol, F &f) {
  f = reinterpret_cast<F>(dlsym(library, symbol));
  return f != nullptr;
}

void append(void *context, void *data, int size) {
  auto *out = static_cast<std::vector<std::uint8_t> *>(context);
  const auto *bytes = static_cast<const std::uint8_t *>(data);
  out->insert(out->end(), bytes, bytes + size);
}

} // namespace

JpegDecoder::JpegDecoder() : turbo_(std::make_unique<Turbo>()) {
  turbo_->library = dlopen(CAMHEAD_TURBOJPEG_SONAME, RTLD_NOW | RTLD_LOCAL);
  if (turbo_->library == nullptr) {
    const char *why = dlerror();
    throw JpegError("MJPEG needs libjpeg-turbo: " +
                    std::string(why != nullptr ? why : CAMHEAD_TURBOJPEG_SONAME " does not open") +
                    " (apt-get install libturbojpeg0)");
  }
  if (!resolve(turbo_->library, "tjInitDecompress", turbo_->init) ||
      !resolve(turbo_->library, "tjDecompressHeader3", turbo_->header) ||
      !resolve(turbo_->library, "tjDecompress2", turbo_->decompress) ||
      !resolve(turbo_->library, "tjGetErrorStr2", turbo_->error_text) ||
      !resolve(turbo_->library, "tjDestroy", turbo_->destroy))
    throw JpegError("MJPEG: " CAMHEAD_TURBOJPEG_SONAME " lacks the TurboJPEG 2 functions");
  turbo_->handle = turbo_->init();
  if (turbo_->handle == nullptr)
    throw JpegError("MJPEG: libjpeg-turbo cannot make a decompressor");
}

JpegDecoder::~JpegDecoder() = default;

bool JpegDecoder::refuse(std::string &error, std::string reason) {
  error = std::move(reason);
  // libjpeg-turbo 2.1 can leave a decompressor mid-header after a frame cut
  // short in its tables (the header then "reads" as 0x0), and the next
  // frame's tables are misread ("Bogus Huffman table definition"): after a
  // frame it could not read, the next one gets a fresh decompressor. Without
  // memory for one, every later frame is refused.
  turbo_->destroy(turbo_->handle);
  turbo_->handle = turbo_->init();
  return false;
}

bool JpegDecoder::decode_rgb(std::span<const std::uint8_t> jpeg, int width, int height,
                             std::span<std::uint8_t> rgb, std::string &error) {
  if (jpeg.empty() || jpeg.size() > std::size_t(INT_MAX)) {
    error = "JPEG: empty frame";
    return false;
  }
  if (turbo_->handle == nullptr) {
    error = "JPEG: no decompressor (out of memory)";
    turbo_->handle = turbo_->init();
    return false;
  }
  const auto length = static_cast<unsigned long>(jpeg.size());
  // The header first: a frame of another size is refused before the
  // decoder allocates for it.
  int w = 0, h = 0, subsampling = 0, colorspace = 0;
  if (turbo_->header(turbo_->handle, jpeg.data(), length, &w, &h, &subsampling, &colorspace) != 0)
    return refuse(error, "JPEG: not a JPEG frame (" + turbo_->reason() + ")");
  if (w <= 0 || h <= 0)
    return refuse(error, "JPEG: not a JPEG frame (no frame header)");
  if (w != width || h != height) { // a header read whole: the decompressor is sound
    error = "JPEG: the frame is " + std::to_string(w) + "x" + std::to_string(h) + ", not " +
            std::to_string(width) + "x" + std::to_string(height);
    return false;
  }
  if (rgb.size() < std::size_t(width) * std::size_t(height) * 3) {
    error = "JPEG: the buffer holds " + std::to_string(rgb.size()) + " bytes, not a " +
            std::to_string(width) + "x" + std::to_string(height) + " RGB frame";
    return false;
  }
  // A warning (data cut short or corrupt, the rest painted grey) fails the
  // frame as an error does: a camera's broken frame is not shown.
  if (turbo_->decompress(turbo_->handle, jpeg.data(), length, rgb.data(), width, 0, height,
                         TJPF_RGB, 0) != 0)
    return refuse(error, "JPEG: cannot decode (" + turbo_->reason() + ")");
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
