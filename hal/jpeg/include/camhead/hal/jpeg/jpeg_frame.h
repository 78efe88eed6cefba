// JPEG frames (a webcam's MJPEG) to 8-bit RGB, through stb_image with only
// its JPEG decoder compiled in, into a buffer the caller owns. Most USB
// webcams give 720p and above only as MJPEG; the renderer takes RGB.
//
// Thread safety: free functions on their arguments.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace camhead::hal::jpeg {

// Decodes `jpeg` into `rgb` (width x height x 3, packed rows). The size in
// the JPEG header is checked against width x height before anything is
// decoded; false with `error` ("JPEG: REASON") for a frame that is not a
// JPEG, is truncated past decoding, or has another size.
[[nodiscard]] bool decode_jpeg_rgb(std::span<const std::uint8_t> jpeg, int width, int height,
                                   std::span<std::uint8_t> rgb, std::string &error);

// `rgb` (width x height x 3) as a baseline JPEG of `quality` (1-100): what a
// test or a simulated MJPEG device sends.
[[nodiscard]] std::vector<std::uint8_t> encode_jpeg_rgb(std::span<const std::uint8_t> rgb,
                                                        int width, int height, int quality);

} // namespace camhead::hal::jpeg
