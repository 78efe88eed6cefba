// A camera frame's luma plane for the marker tracker: Y' as captured from
// the Y'CbCr formats, BT.601 weights from the RGB ones, rows at the frame's
// stride, and the range its codes span; and no allocation on the capture
// thread that calls it.
#include <cstdint>
#include <vector>

#include "counting_new.h"
#include "tracking/luma.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

using base::PixelFormat;

constexpr int kW = 4, kH = 2;

base::VideoFormat format(PixelFormat pixel, int stride = 0) {
  base::VideoFormat f;
  f.pixel = pixel;
  f.width = kW;
  f.height = kH;
  f.stride = stride;
  return f;
}

// Y' of pixel (x, y): distinct everywhere.
std::uint8_t luma_at(int x, int y) {
  return std::uint8_t(20 + 30 * y + 7 * x);
}

std::vector<std::uint8_t> copied(const base::VideoFormat &f, const std::vector<std::uint8_t> &in) {
  std::vector<std::uint8_t> out(kW * kH, 0);
  copy_luma(f, in, out);
  return out;
}

std::vector<std::uint8_t> expected() {
  std::vector<std::uint8_t> e;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      e.push_back(luma_at(x, y));
  return e;
}

TEST(Luma, YuyvTakesEveryOtherByteAtTheStride) {
  const base::VideoFormat f = format(PixelFormat::yuyv, 12); // 4 bytes of padding a row
  std::vector<std::uint8_t> frame(base::frame_bytes(f), 128);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      frame[std::size_t(y * 12 + 2 * x)] = luma_at(x, y);
  EXPECT_EQ(copied(f, frame), expected());
}

TEST(Luma, Nv12TakesItsFirstPlane) {
  const base::VideoFormat f = format(PixelFormat::nv12);
  std::vector<std::uint8_t> frame(base::frame_bytes(f), 128);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      frame[std::size_t(y * kW + x)] = luma_at(x, y);
  EXPECT_EQ(copied(f, frame), expected());
}

TEST(Luma, RgbFormatsWeighTheirChannelsAsBt601) {
  // Pure red, green, blue and white: 0.299, 0.587, 0.114 of 200, and 200.
  const std::uint8_t want[] = {60, 117, 23, 200};
  for (const PixelFormat pixel : {PixelFormat::rgb24, PixelFormat::bgr24, PixelFormat::xrgb8888}) {
    const base::VideoFormat f = format(pixel);
    const std::size_t step = pixel == PixelFormat::xrgb8888 ? 4 : 3;
    std::vector<std::uint8_t> frame(base::frame_bytes(f), 0);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        std::uint8_t *p = &frame[std::size_t(y) * base::row_bytes(f) + step * std::size_t(x)];
        // In memory: rgb24 R G B; bgr24 and xrgb8888 B G R (X).
        const std::size_t r = pixel == PixelFormat::rgb24 ? 0 : 2, b = 2 - r;
        if (x == 0 || x == 3)
          p[r] = 200;
        if (x == 1 || x == 3)
          p[1] = 200;
        if (x == 2 || x == 3)
          p[b] = 200;
      }
    const std::vector<std::uint8_t> got = copied(f, frame);
    for (int x = 0; x < kW; ++x)
      EXPECT_NEAR(got[std::size_t(x)], want[x], 1) << base::pixel_format_name(pixel) << " x " << x;
  }
}

// Y'CbCr video's codes span 16-235 unless its format says full range; RGB
// is always full. A view saved for `calibrate camera` (an 8-bit grey PNG,
// full range by definition) is stretched: black to 0, white to 255, the
// steps between rounded, and the foot- and headroom clipped.
TEST(Luma, TheRangeOfTheCodesFollowsTheFormat) {
  base::VideoFormat yuv = format(PixelFormat::nv12);
  EXPECT_TRUE(luma_limited_range(yuv));
  yuv.range = base::ColorRange::full;
  EXPECT_FALSE(luma_limited_range(yuv));
  EXPECT_FALSE(luma_limited_range(format(PixelFormat::rgb24)));

  std::vector<std::uint8_t> codes = {0, 15, 16, 17, 126, 235, 236, 255};
  luma_to_full_range(codes);
  EXPECT_EQ(codes, (std::vector<std::uint8_t>{0, 0, 0, 1, 128, 255, 255, 255}));
}

TEST(Luma, CopyingAllocatesNothing) {
  const base::VideoFormat f = format(PixelFormat::yuyv);
  const std::vector<std::uint8_t> frame(base::frame_bytes(f), 100);
  std::vector<std::uint8_t> out(kW * kH);
  camhead::test::counting_new::start([] { return 0; });
  for (int i = 0; i < 100; ++i)
    copy_luma(f, frame, out);
  camhead::test::counting_new::stop();
  EXPECT_EQ(camhead::test::counting_new::count(0), 0u);
}

} // namespace
} // namespace camhead::pipeline
