// JPEG frames (a webcam's MJPEG) to 8-bit RGB, into a buffer the caller
// owns. Most USB webcams give 720p and above only as MJPEG; the renderer
// takes RGB. Decoded by libjpeg-turbo's TurboJPEG (Debian's libturbojpeg0),
// opened at run time when an MJPEG stream starts, so that camhead itself
// needs only Vulkan and the C++ runtime: 2.5 times as fast as the
// stb_image decoder it replaced, at 720p and 1080p (bench/RESULTS.md), and
// a maintained, hardened decoder for what a device anyone may plug in sends
// (Debian 12's stb_image wrote past a Huffman table on a frame that
// jpeg_fuzz found in seconds).
//
// Thread safety: a decoder is used by one thread at a time (one per camera
// stream); encode_jpeg_rgb is a free function on its arguments.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace camhead::hal::jpeg {

class JpegError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

class JpegDecoder {
public:
  // Throws JpegError, naming the package, where libturbojpeg.so.0 does not
  // open.
  JpegDecoder();
  ~JpegDecoder();
  JpegDecoder(const JpegDecoder &) = delete;
  JpegDecoder &operator=(const JpegDecoder &) = delete;

  // Decodes `jpeg` into `rgb` (width x height x 3, packed rows). The size
  // in the JPEG header is checked against width x height before anything
  // is decoded; false with `error` ("JPEG: REASON") for a frame that is not
  // a JPEG, is truncated or corrupt (libjpeg-turbo's warnings included), or
  // has another size.
  [[nodiscard]] bool decode_rgb(std::span<const std::uint8_t> jpeg, int width, int height,
                                std::span<std::uint8_t> rgb, std::string &error);

private:
  struct Turbo;
  bool refuse(std::string &error, std::string reason);
  std::unique_ptr<Turbo> turbo_;
};

// `rgb` (width x height x 3) as a baseline JPEG of `quality` (1-100): what a
// test or a simulated MJPEG device sends.
[[nodiscard]] std::vector<std::uint8_t> encode_jpeg_rgb(std::span<const std::uint8_t> rgb,
                                                        int width, int height, int quality);

} // namespace camhead::hal::jpeg
