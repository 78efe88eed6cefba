// A Y4M file written by the sink reads back through the file camera byte for
// byte, in both YUV formats; hand-written files from other writers are
// repacked as nv12 / yuyv correctly.
#include <string>
#include <vector>

#include "camhead/hal/camera/file/file_camera.h"
#include "camhead/hal/output/file/file_sink.h"
#include "video_test_files.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using base::ColorRange;
using base::PixelFormat;
using hal::camera::CapturedFrame;
using hal::camera::CaptureResult;

std::unique_ptr<hal::camera::CameraSource> play_once(const std::filesystem::path &path) {
  hal::camera::FileCameraOptions options;
  options.path = path;
  options.realtime = false;
  return hal::camera::open_file_camera(options);
}

void expect_round_trip(const base::VideoFormat &format) {
  const test::ScratchDir dir;
  std::vector<std::vector<std::uint8_t>> frames;
  for (int i = 0; i < 5; ++i)
    frames.push_back(test::generated_frame(format, i));
  auto sink = hal::output::open_y4m_sink(dir / "take.y4m", format, 25.0);
  test::write_all(*sink, frames);
  EXPECT_EQ(sink->status().frames, 5u);

  auto camera = play_once(dir / "take.y4m");
  EXPECT_EQ(camera->format(), format);
  EXPECT_EQ(camera->frame_interval_ns(), 40'000'000);
  const auto read = test::read_all(*camera);
  ASSERT_EQ(read.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i)
    EXPECT_EQ(read[i], frames[i]) << "frame " << i;
  CapturedFrame frame;
  EXPECT_EQ(camera->wait_frame(std::chrono::milliseconds(0), frame), CaptureResult::ended);
  const auto status = camera->status();
  EXPECT_FALSE(status.connected);
  EXPECT_EQ(status.frames, 5u);
  EXPECT_EQ(status.errors, 0u);
  EXPECT_NE(status.detail.find("ended after 5 frames"), std::string::npos) << status.detail;
}

TEST(Y4mRoundTrip, YuyvByteExact) {
  expect_round_trip(test::make_format(PixelFormat::yuyv, 64, 36));
}

TEST(Y4mRoundTrip, Nv12FullRangeByteExact) {
  expect_round_trip(test::make_format(PixelFormat::nv12, 64, 36, ColorRange::full));
}

TEST(Y4mRoundTrip, Nv12OddSizedChromaRows) {
  // 38 rows: 19 chroma rows, so a plane boundary off by a row would show.
  expect_round_trip(test::make_format(PixelFormat::nv12, 22, 38));
}

TEST(Y4mRoundTrip, Planar420IsInterleavedAsNv12) {
  const test::ScratchDir dir;
  // No XCOLORRANGE (limited); FRAME parameters are allowed and ignored.
  test::write_text(dir / "jpeg.y4m", "YUV4MPEG2 W4 H2 F25:1 Ip C420jpeg\n"
                                     "FRAME Ixyz\n"
                                     "\x01\x02\x03\x04\x05\x06\x07\x08"
                                     "\x64\x65"
                                     "\xc8\xc9");
  auto camera = play_once(dir / "jpeg.y4m");
  EXPECT_EQ(camera->format(), test::make_format(PixelFormat::nv12, 4, 2, ColorRange::limited));
  const auto read = test::read_all(*camera);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0], (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6, 7, 8, 0x64, 0xc8, 0x65, 0xc9}));
}

TEST(Y4mRoundTrip, Planar422IsPackedAsYuyv) {
  const test::ScratchDir dir;
  test::write_text(dir / "422.y4m", "YUV4MPEG2 W4 H1 F50:1 Ip A1:1 C422 "
                                    "XCOLORRANGE=FULL\nFRAME\n"
                                    "\x01\x02\x03\x04"
                                    "\x64\x65"
                                    "\xc8\xc9");
  auto camera = play_once(dir / "422.y4m");
  EXPECT_EQ(camera->format(), test::make_format(PixelFormat::yuyv, 4, 1, ColorRange::full));
  EXPECT_EQ(camera->frame_interval_ns(), 20'000'000);
  const auto read = test::read_all(*camera);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0], (std::vector<std::uint8_t>{1, 0x64, 2, 0xc8, 3, 0x65, 4, 0xc9}));
}

} // namespace
} // namespace camhead
