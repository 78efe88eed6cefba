// MJPEG frames to RGB: a frame a webcam would send decodes to the picture
// within JPEG's loss; a frame of another size, a truncated or a foreign one
// is refused with the reason, before it is decoded.
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
  const int w = 64, h = 48;
  const std::vector<std::uint8_t> picture = ramps(w, h);
  const std::vector<std::uint8_t> jpeg = encode_jpeg_rgb(picture, w, h, 95);
  ASSERT_GT(jpeg.size(), 100u);
  std::vector<std::uint8_t> rgb(picture.size());
  std::string error;
  ASSERT_TRUE(decode_jpeg_rgb(jpeg, w, h, rgb, error)) << error;
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

TEST(JpegFrame, RefusesWhatItCannotUse) {
  const int w = 32, h = 16;
  const std::vector<std::uint8_t> jpeg = encode_jpeg_rgb(ramps(w, h), w, h, 90);
  std::vector<std::uint8_t> rgb(std::size_t(w) * h * 3);
  std::string error;
  EXPECT_FALSE(decode_jpeg_rgb(jpeg, 64, 48, rgb, error));
  EXPECT_EQ(error, "JPEG: the frame is 32x16, not 64x48");
  const std::vector<std::uint8_t> junk(200, 0x55);
  EXPECT_FALSE(decode_jpeg_rgb(junk, w, h, rgb, error));
  EXPECT_EQ(error.rfind("JPEG: not a JPEG frame", 0), 0u) << error;
  EXPECT_FALSE(decode_jpeg_rgb({}, w, h, rgb, error));
  EXPECT_EQ(error, "JPEG: empty frame");
  std::vector<std::uint8_t> small(10);
  EXPECT_FALSE(decode_jpeg_rgb(jpeg, w, h, small, error));
  EXPECT_NE(error.find("holds 10 bytes"), std::string::npos) << error;
  // Cut inside the entropy-coded data: stb either refuses it or decodes
  // what is there; either way nothing is written past the buffer (ASan).
  const std::vector<std::uint8_t> cut(jpeg.begin(), jpeg.begin() + jpeg.size() / 2);
  (void)decode_jpeg_rgb(cut, w, h, rgb, error);
}

} // namespace
} // namespace camhead::hal::jpeg
