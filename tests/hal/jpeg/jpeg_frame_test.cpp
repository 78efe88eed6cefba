// MJPEG frames to RGB (libjpeg-turbo, opened at run time): a frame a webcam
// would send decodes to the picture within JPEG's loss; a frame of another
// size, a truncated, corrupt or foreign one is refused with the reason, and
// the decoder takes the next good frame after any of them.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "camhead/hal/jpeg/jpeg_frame.h"

#include <gtest/gtest.h>

namespace camhead::hal::jpeg {
namespace {

// Smooth colour ramps, what JPEG keeps well.
std::vector<std::uint8_t> ramps(int w, int h) {
  std::vector<std::uint8_t> rgb(std::size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t *p = &rgb[(std::size_t(y) * w + x) * 3];
      p[0] = std::uint8_t(255 * x / (w - 1));
      p[1] = std::uint8_t(255 * y / (h - 1));
      p[2] = std::uint8_t(128);
    }
  return rgb;
}

TEST(JpegFrame, AWebcamFrameDecodesToThePicture) {
  JpegDecoder decoder;
  const int w = 64, h = 48;
  const std::vector<std::uint8_t> picture = ramps(w, h);
  const std::vector<std::uint8_t> jpeg = encode_jpeg_rgb(picture, w, h, 95);
  ASSERT_GT(jpeg.size(), 100u);
  std::vector<std::uint8_t> rgb(picture.size());
  std::string error;
  ASSERT_TRUE(decoder.decode_rgb(jpeg, w, h, rgb, error)) << error;
  double sum = 0.0;
  int worst = 0;
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    const int d = std::abs(int(rgb[i]) - int(picture[i]));
    worst = std::max(worst, d);
    sum += d;
  }
  EXPECT_LT(sum / double(rgb.size()), 2.0) << "mean error in code values";
  EXPECT_LE(worst, 16);
}

TEST(JpegFrame, RefusesWhatItCannotUseAndTakesTheNextGoodFrame) {
  JpegDecoder decoder;
  const int w = 32, h = 16;
  const std::vector<std::uint8_t> jpeg = encode_jpeg_rgb(ramps(w, h), w, h, 90);
  std::vector<std::uint8_t> rgb(std::size_t(w) * h * 3);
  std::string error;
  EXPECT_FALSE(decoder.decode_rgb(jpeg, 64, 48, rgb, error));
  EXPECT_EQ(error, "JPEG: the frame is 32x16, not 64x48");
  const std::vector<std::uint8_t> junk(200, 0x55);
  EXPECT_FALSE(decoder.decode_rgb(junk, w, h, rgb, error));
  EXPECT_EQ(error.rfind("JPEG: not a JPEG frame", 0), 0u) << error;
  EXPECT_FALSE(decoder.decode_rgb({}, w, h, rgb, error));
  EXPECT_EQ(error, "JPEG: empty frame");
  std::vector<std::uint8_t> small(10);
  EXPECT_FALSE(decoder.decode_rgb(jpeg, w, h, small, error));
  EXPECT_NE(error.find("holds 10 bytes"), std::string::npos) << error;
  // Cut in half (inside its tables): refused.
  const std::vector<std::uint8_t> cut(jpeg.begin(), jpeg.begin() + jpeg.size() / 2);
  EXPECT_FALSE(decoder.decode_rgb(cut, w, h, rgb, error));
  EXPECT_EQ(error.rfind("JPEG: not a JPEG frame", 0), 0u) << error;
  // Cut inside the entropy-coded data, the headers whole: libjpeg-turbo
  // would paint the rest grey and warn; the frame is refused.
  const std::vector<std::uint8_t> large = encode_jpeg_rgb(ramps(320, 240), 320, 240, 95);
  const std::vector<std::uint8_t> short_data(large.begin(), large.end() - 200);
  std::vector<std::uint8_t> out(320 * 240 * 3);
  EXPECT_FALSE(decoder.decode_rgb(short_data, 320, 240, out, error));
  EXPECT_EQ(error, "JPEG: cannot decode (Premature end of JPEG file)");
  // After all of them, a good frame decodes (a frame cut in its tables
  // once left libjpeg-turbo's decompressor misreading the next one).
  EXPECT_TRUE(decoder.decode_rgb(jpeg, w, h, rgb, error)) << error;
  EXPECT_TRUE(decoder.decode_rgb(large, 320, 240, out, error)) << error;
}

} // namespace
} // namespace camhead::hal::jpeg
