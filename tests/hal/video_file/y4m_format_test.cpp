// The Y4M bytes the sink writes, checked against a header and plane layout
// written out by hand in ffmpeg's convention; the header parser on the
// headers other writers produce; frame rates as ratios; frame patterns.
#include <cmath>
#include <string>
#include <vector>

#include "camhead/hal/output/file/file_sink.h"
#include "camhead/hal/video_file/frame_pattern.h"
#include "camhead/hal/video_file/y4m_header.h"
#include "video_test_files.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using base::ColorRange;
using base::PixelFormat;
using hal::video_file::FramePattern;

std::string bytes_text(const std::vector<std::uint8_t> &bytes) {
  return {bytes.begin(), bytes.end()};
}

TEST(Y4mFormat, YuyvIsWrittenAsC422WithFfmpegsHeader) {
  const test::ScratchDir dir;
  // Y0 Cb Y1 Cr pairs; the planes are Y 10..17, Cb 20..23, Cr 30..33.
  const std::vector<std::uint8_t> frame = {10, 20, 11, 30, 12, 21, 13, 31,
                                           14, 22, 15, 32, 16, 23, 17, 33};
  auto sink =
      hal::output::open_y4m_sink(dir / "a.y4m", test::make_format(PixelFormat::yuyv, 4, 2), 25.0);
  test::write_all(*sink, {frame, frame});
  const std::string frame_record =
      "FRAME\n" + bytes_text({10, 11, 12, 13, 14, 15, 16, 17, 20, 21, 22, 23, 30, 31, 32, 33});
  EXPECT_EQ(test::read_text(dir / "a.y4m"),
            "YUV4MPEG2 W4 H2 F25:1 Ip A1:1 C422 XCOLORRANGE=LIMITED\n" + frame_record +
                frame_record);
}

TEST(Y4mFormat, Nv12IsWrittenAsC420mpeg2WithItsRange) {
  const test::ScratchDir dir;
  const std::vector<std::uint8_t> frame = {0, 1, 2, 3, 4, 5, 6, 7, 100, 200, 101, 201};
  auto sink = hal::output::open_y4m_sink(
      dir / "b.y4m", test::make_format(PixelFormat::nv12, 4, 2, ColorRange::full), 30000.0 / 1001);
  test::write_all(*sink, {frame});
  EXPECT_EQ(test::read_text(dir / "b.y4m"),
            "YUV4MPEG2 W4 H2 F30000:1001 Ip A1:1 C420mpeg2 XCOLORRANGE=FULL\n"
            "FRAME\n" +
                bytes_text({0, 1, 2, 3, 4, 5, 6, 7, 100, 101, 200, 201}));
}

TEST(Y4mFormat, ReadsWhatOtherWritersWrite) {
  std::string error;
  // ffmpeg: unknown aspect, mjpegtools' XYSCSS note.
  auto h = hal::video_file::parse_y4m_header(
      "YUV4MPEG2 W720 H576 F25:1 Ip A0:0 C420jpeg XYSCSS=420JPEG XCOLORRANGE=FULL", error);
  ASSERT_TRUE(h) << error;
  EXPECT_EQ(h->width, 720);
  EXPECT_EQ(h->height, 576);
  EXPECT_EQ(h->range, ColorRange::full);
  EXPECT_EQ(hal::video_file::y4m_video_format(*h).pixel, PixelFormat::nv12);
  // libvpx: no A, no range (limited), no trailing fields.
  h = hal::video_file::parse_y4m_header("YUV4MPEG2 W352 H288 F30000:1001 Ip C422", error);
  ASSERT_TRUE(h) << error;
  EXPECT_EQ(h->range, ColorRange::limited);
  EXPECT_EQ(hal::video_file::y4m_video_format(*h).pixel, PixelFormat::yuyv);
  EXPECT_EQ(hal::video_file::y4m_video_format(*h).matrix, base::ColorMatrix::bt709);
  // The bare minimum: C defaults to 420jpeg, I to progressive, F unknown.
  h = hal::video_file::parse_y4m_header("YUV4MPEG2 W2 H2", error);
  ASSERT_TRUE(h) << error;
  EXPECT_EQ(h->chroma, hal::video_file::Y4mChroma::c420jpeg);
  EXPECT_EQ(h->rate_num, 0u);
}

TEST(Y4mFormat, FrameRatesAsRatios) {
  const auto ratio = [](double fps) {
    const auto r = hal::video_file::y4m_rate_from_fps(fps);
    return r ? std::to_string(r->num) + ":" + std::to_string(r->den) : std::string("none");
  };
  EXPECT_EQ(ratio(25), "25:1");
  EXPECT_EQ(ratio(30000.0 / 1001), "30000:1001");
  EXPECT_EQ(ratio(29.97), "30000:1001");
  EXPECT_EQ(ratio(23.976), "24000:1001");
  EXPECT_EQ(ratio(59.94), "60000:1001");
  EXPECT_EQ(ratio(12.5), "25:2");
  EXPECT_EQ(ratio(0), "none");
  EXPECT_EQ(ratio(-25), "none");
  EXPECT_EQ(ratio(5000), "none");
  EXPECT_EQ(ratio(std::nan("")), "none");
  EXPECT_EQ(hal::video_file::y4m_frame_interval_ns(25, 1), 40'000'000);
  EXPECT_EQ(hal::video_file::y4m_frame_interval_ns(30000, 1001), 33'366'667);
  EXPECT_EQ(hal::video_file::y4m_frame_interval_ns(0, 0), 0);
}

TEST(FramePattern, FormatsNumbersWithoutPrintf) {
  std::string error;
  auto p = FramePattern::parse("out/%05d.png", error);
  ASSERT_TRUE(p) << error;
  EXPECT_EQ(p->path(12), "out/00012.png");
  EXPECT_EQ(p->path(1234567), "out/1234567.png");
  p = FramePattern::parse("%d.png", error);
  ASSERT_TRUE(p) << error;
  EXPECT_EQ(p->path(7), "7.png");
  p = FramePattern::parse("100%%/take_%3u.png", error);
  ASSERT_TRUE(p) << error;
  EXPECT_EQ(p->path(7), "100%/take_  7.png");
}

TEST(FramePattern, NeedsExactlyOneNumber) {
  std::string error;
  EXPECT_FALSE(FramePattern::parse("out/frame.png", error));
  EXPECT_NE(error.find("exactly one"), std::string::npos) << error;
  EXPECT_FALSE(FramePattern::parse("out/%d_%d.png", error));
  EXPECT_NE(error.find("exactly one"), std::string::npos) << error;
  EXPECT_FALSE(FramePattern::parse("out/%s.png", error));
  EXPECT_NE(error.find("'%s'"), std::string::npos) << error;
  EXPECT_FALSE(FramePattern::parse("out/%123d.png", error));
  EXPECT_FALSE(FramePattern::parse("out/%", error));
}

} // namespace
} // namespace camhead
