// Formats, colour and frame rates between V4L2 and camhead
// (camhead/hal/v4l2/pixel_formats.h).
#include <cmath>
#include <string>

#include <linux/videodev2.h>

#include "camhead/hal/v4l2/pixel_formats.h"

#include <gtest/gtest.h>

namespace camhead::hal::v4l2 {
namespace {

using base::ColorMatrix;
using base::ColorRange;
using base::PixelFormat;

v4l2_pix_format pix(std::uint32_t height, std::uint32_t colorspace, std::uint32_t enc,
                    std::uint32_t quantization) {
  v4l2_pix_format p{};
  p.width = 640;
  p.height = height;
  p.pixelformat = V4L2_PIX_FMT_YUYV;
  p.field = V4L2_FIELD_NONE;
  p.priv = V4L2_PIX_FMT_PRIV_MAGIC;
  p.colorspace = colorspace;
  p.ycbcr_enc = enc;
  p.quantization = quantization;
  return p;
}

Colour colour(const v4l2_pix_format &p) {
  std::string error;
  const auto c = colour_of(p, error);
  EXPECT_TRUE(c) << error;
  return c.value_or(Colour{});
}

TEST(V4l2PixelFormats, CameraFormatsMapBothWays) {
  for (const PixelFormat format :
       {PixelFormat::yuyv, PixelFormat::nv12, PixelFormat::rgb24, PixelFormat::bgr24}) {
    const auto fourcc = fourcc_of(format);
    ASSERT_TRUE(fourcc);
    EXPECT_EQ(pixel_format_of(*fourcc), format);
  }
  EXPECT_EQ(fourcc_of(PixelFormat::yuyv), V4L2_PIX_FMT_YUYV);
  EXPECT_EQ(fourcc_of(PixelFormat::nv12), V4L2_PIX_FMT_NV12);
  EXPECT_EQ(fourcc_of(PixelFormat::rgb24), V4L2_PIX_FMT_RGB24);
  EXPECT_EQ(fourcc_of(PixelFormat::bgr24), V4L2_PIX_FMT_BGR24);
  EXPECT_FALSE(fourcc_of(PixelFormat::xrgb8888));
  EXPECT_FALSE(pixel_format_of(V4L2_PIX_FMT_MJPEG));
}

TEST(V4l2PixelFormats, FourccTextAndJpeg) {
  EXPECT_EQ(fourcc_text(V4L2_PIX_FMT_YUYV), "YUYV");
  EXPECT_EQ(fourcc_text(V4L2_PIX_FMT_MJPEG), "MJPG");
  EXPECT_EQ(fourcc_text(V4L2_PIX_FMT_RGB24), "RGB3");
  EXPECT_EQ(fourcc_text(0x01020304), "0x01020304");
  EXPECT_TRUE(is_jpeg(V4L2_PIX_FMT_MJPEG));
  EXPECT_TRUE(is_jpeg(V4L2_PIX_FMT_JPEG));
  EXPECT_FALSE(is_jpeg(V4L2_PIX_FMT_YUYV));
}

TEST(V4l2PixelFormats, DescribeNamesSizeFormatAndFields) {
  v4l2_pix_format p = pix(480, 0, 0, 0);
  EXPECT_EQ(describe(p), "640x480 YUYV");
  p.field = V4L2_FIELD_ALTERNATE;
  EXPECT_EQ(describe(p), "640x480 YUYV (alternate fields)");
}

TEST(V4l2PixelFormats, WholeFramesAreProgressiveOrWoven) {
  EXPECT_TRUE(is_whole_frame(V4L2_FIELD_NONE));
  EXPECT_TRUE(is_whole_frame(V4L2_FIELD_INTERLACED));
  EXPECT_TRUE(is_whole_frame(V4L2_FIELD_INTERLACED_TB));
  EXPECT_FALSE(is_whole_frame(V4L2_FIELD_TOP));
  EXPECT_FALSE(is_whole_frame(V4L2_FIELD_ALTERNATE));
  EXPECT_FALSE(is_whole_frame(V4L2_FIELD_SEQ_TB));
}

TEST(V4l2Colour, DriverEncodingAndQuantizationWin) {
  const Colour c =
      colour(pix(480, V4L2_COLORSPACE_SRGB, V4L2_YCBCR_ENC_709, V4L2_QUANTIZATION_FULL_RANGE));
  EXPECT_EQ(c.matrix, ColorMatrix::bt709);
  EXPECT_EQ(c.range, ColorRange::full);
  const Colour d =
      colour(pix(1080, V4L2_COLORSPACE_REC709, V4L2_YCBCR_ENC_601, V4L2_QUANTIZATION_LIM_RANGE));
  EXPECT_EQ(d.matrix, ColorMatrix::bt601);
  EXPECT_EQ(d.range, ColorRange::limited);
}

TEST(V4l2Colour, ColorspaceGivesTheDefaultsV4l2Defines) {
  // sRGB is what UVC webcams report: BT.601 limited at any size.
  const Colour srgb = colour(pix(1080, V4L2_COLORSPACE_SRGB, 0, 0));
  EXPECT_EQ(srgb.matrix, ColorMatrix::bt601);
  EXPECT_EQ(srgb.range, ColorRange::limited);
  const Colour rec709 = colour(pix(480, V4L2_COLORSPACE_REC709, 0, 0));
  EXPECT_EQ(rec709.matrix, ColorMatrix::bt709);
  EXPECT_EQ(rec709.range, ColorRange::limited);
  const Colour jpeg = colour(pix(480, V4L2_COLORSPACE_JPEG, 0, 0));
  EXPECT_EQ(jpeg.matrix, ColorMatrix::bt601);
  EXPECT_EQ(jpeg.range, ColorRange::full);
  EXPECT_EQ(colour(pix(576, V4L2_COLORSPACE_SMPTE170M, 0, 0)).matrix, ColorMatrix::bt601);
}

TEST(V4l2Colour, NothingSaidMeansSdBt601AndHdBt709Limited) {
  const Colour sd = colour(pix(576, V4L2_COLORSPACE_DEFAULT, 0, 0));
  EXPECT_EQ(sd.matrix, ColorMatrix::bt601);
  EXPECT_EQ(sd.range, ColorRange::limited);
  const Colour hd = colour(pix(720, V4L2_COLORSPACE_DEFAULT, 0, 0));
  EXPECT_EQ(hd.matrix, ColorMatrix::bt709);
  EXPECT_EQ(hd.range, ColorRange::limited);
}

TEST(V4l2Colour, ExtendedFieldsWithoutTheMagicAreUnset) {
  v4l2_pix_format p =
      pix(720, V4L2_COLORSPACE_DEFAULT, V4L2_YCBCR_ENC_601, V4L2_QUANTIZATION_FULL_RANGE);
  p.priv = 0;
  const Colour c = colour(p);
  EXPECT_EQ(c.matrix, ColorMatrix::bt709);
  EXPECT_EQ(c.range, ColorRange::limited);
}

TEST(V4l2Colour, EncodingsCamheadCannotConvertAreRefusedByName) {
  std::string error;
  EXPECT_FALSE(colour_of(pix(2160, V4L2_COLORSPACE_BT2020, 0, 0), error));
  EXPECT_NE(error.find("BT.2020"), std::string::npos) << error;
  EXPECT_FALSE(colour_of(pix(1080, V4L2_COLORSPACE_SRGB, V4L2_YCBCR_ENC_SMPTE240M, 0), error));
  EXPECT_NE(error.find("SMPTE 240M"), std::string::npos) << error;
}

TEST(V4l2Colour, SetColourReadsBackTheSame) {
  for (const ColorMatrix matrix : {ColorMatrix::bt601, ColorMatrix::bt709}) {
    for (const ColorRange range : {ColorRange::limited, ColorRange::full}) {
      base::VideoFormat format{PixelFormat::nv12, 1280, 720};
      format.matrix = matrix;
      format.range = range;
      v4l2_pix_format p{};
      p.height = 720;
      set_colour(p, format);
      const Colour c = colour(p);
      EXPECT_EQ(c.matrix, matrix);
      EXPECT_EQ(c.range, range);
    }
  }
}

TEST(V4l2FramePeriod, IntegerAndNtscRates) {
  const auto expect = [](double fps, std::uint32_t num, std::uint32_t den) {
    const auto period = frame_period(fps);
    ASSERT_TRUE(period) << fps;
    EXPECT_EQ(period->numerator, num) << fps;
    EXPECT_EQ(period->denominator, den) << fps;
  };
  expect(25, 1, 25);
  expect(30, 1, 30);
  expect(29.97, 1001, 30000);
  expect(59.94, 1001, 60000);
  expect(23.976, 1001, 24000);
  expect(0.5, 2, 1);
  expect(12.5, 2, 25);
  EXPECT_FALSE(frame_period(0));
  EXPECT_FALSE(frame_period(-25));
  EXPECT_FALSE(frame_period(1001));
  EXPECT_FALSE(frame_period(std::nan("")));
}

TEST(V4l2FramePeriod, NanosecondsAndText) {
  EXPECT_EQ(period_ns({1, 25}), 40'000'000);
  EXPECT_EQ(period_ns({1001, 30000}), 33'366'667);
  EXPECT_EQ(period_ns({0, 0}), 0);
  EXPECT_EQ(period_ns({1, 0}), 0);
  EXPECT_EQ(rate_text({1, 25}), "25 fps");
  EXPECT_EQ(rate_text({1001, 30000}), "29.97 fps");
  EXPECT_EQ(rate_text({0, 0}), "an unknown rate");
}

} // namespace
} // namespace camhead::hal::v4l2
