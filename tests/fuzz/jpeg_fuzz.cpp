// libFuzzer target for a webcam's MJPEG frames (hal/jpeg): the input is one
// frame as a camera would deliver it, decoded into a 64x48 RGB buffer by
// libjpeg-turbo, as the V4L2 camera decodes it. A frame must be refused
// with a "JPEG: " reason or decoded whole, with nothing written past the
// buffer, and a good frame must decode after whatever came before (the
// decompressor renewed after a refusal); the seeds (corpus/jpeg) are 64x48
// frames, so that mutations keep reaching the decoding itself. The system's
// libturbojpeg.so.0 is not instrumented: what is watched is hal/jpeg and
// the buffer it hands the library.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "camhead/hal/jpeg/jpeg_frame.h"
#include "fuzz_check.h"

namespace {

using camhead::fuzz::check;
namespace jpeg = camhead::hal::jpeg;

constexpr int kWidth = 64, kHeight = 48;

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  static jpeg::JpegDecoder decoder;
  static const std::vector<std::uint8_t> good = [] {
    std::vector<std::uint8_t> grey(std::size_t(kWidth) * kHeight * 3, 100);
    return jpeg::encode_jpeg_rgb(grey, kWidth, kHeight, 90);
  }();
  std::vector<std::uint8_t> rgb(std::size_t(kWidth) * kHeight * 3);
  std::string error;
  if (!decoder.decode_rgb(std::span(data, size), kWidth, kHeight, rgb, error))
    check(error.rfind("JPEG: ", 0) == 0);
  check(decoder.decode_rgb(good, kWidth, kHeight, rgb, error));
  return 0;
}
