// The file camera refuses every malformed Y4M header at open, naming the
// field; refuses a file whose first frame is missing or short; and ends a
// stream whose later frame is short or garbled, naming file and frame.
#include <cmath>
#include <string>
#include <vector>

#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/camera/file/file_camera.h"
#include "camhead/hal/output/file/file_sink.h"
#include "video_test_files.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using base::PixelFormat;
using hal::camera::CapturedFrame;
using hal::camera::CaptureResult;
using hal::camera::FileCameraError;
using hal::camera::FileCameraOptions;

// The message open_file_camera throws, or "opened" when it does not.
std::string open_error(const std::filesystem::path &path, double fps = 0) {
  FileCameraOptions options;
  options.path = path;
  options.realtime = false;
  options.fps = fps;
  try {
    auto camera = hal::camera::open_file_camera(options);
  } catch (const FileCameraError &e) {
    return e.what();
  }
  return "opened";
}

struct HeaderCase {
  const char *header; // the line without its '\n'
  const char *error;  // what follows "FILE: header: "
};

const HeaderCase kBadHeaders[] = {
    {"YUV4MPEG2 H2 F25:1", "W missing"},
    {"YUV4MPEG2 W4 F25:1", "H missing"},
    {"YUV4MPEG2 W4 H2", "F missing or 0:0"},
    {"YUV4MPEG2 W4 H2 F0:0", "F missing or 0:0"},
    {"YUV4MPEG2 W0 H2 F25:1", "W '0' is not a positive whole number"},
    {"YUV4MPEG2 Wabc H2 F25:1", "W 'abc' is not"},
    {"YUV4MPEG2 W-4 H2 F25:1", "W '-4' is not"},
    {"YUV4MPEG2 W4 H+2 F25:1", "H '+2' is not"},
    {"YUV4MPEG2 W4 W4 H2 F25:1", "W given twice"},
    {"YUV4MPEG2 W4 H2 F25", "F '25' is not a ratio"},
    {"YUV4MPEG2 W4 H2 F25:0", "F25:0 is not a frame rate"},
    {"YUV4MPEG2 W4 H2 F5000:1", "F5000:1 is outside 0.01 to 1000"},
    {"YUV4MPEG2 W4 H2 F25:1 It", "It: interlaced video is not supported"},
    {"YUV4MPEG2 W4 H2 F25:1 Ib", "Ib: interlaced video is not supported"},
    {"YUV4MPEG2 W4 H2 F25:1 Im", "Im: mixed interlacing"},
    {"YUV4MPEG2 W4 H2 F25:1 I?", "I?: unknown interlacing"},
    {"YUV4MPEG2 W4 H2 F25:1 Ix", "I 'x' is not p, t, b, m or ?"},
    {"YUV4MPEG2 W4 H2 F25:1 A59:54", "A59:54: non-square pixels"},
    {"YUV4MPEG2 W4 H2 F25:1 A1", "A '1' is not a ratio"},
    {"YUV4MPEG2 W4 H2 F25:1 Cmono", "Cmono: greyscale is not supported"},
    {"YUV4MPEG2 W4 H2 F25:1 C444", "C444: 4:4:4 is not supported"},
    {"YUV4MPEG2 W4 H2 F25:1 C444alpha", "C444alpha: 4:4:4 is not supported"},
    {"YUV4MPEG2 W4 H2 F25:1 C420p10", "C420p10: more than 8 bits"},
    {"YUV4MPEG2 W4 H2 F25:1 C411", "C411 is not supported"},
    {"YUV4MPEG2 W4 H2 F25:1 C420jpeg C422", "C given twice"},
    {"YUV4MPEG2 W4 H2 F25:1 XCOLORRANGE=MAYBE", "XCOLORRANGE=MAYBE: the range is FULL or"},
    {"YUV4MPEG2 W4 H2 F25:1 XCOLORRANGE=FULL XCOLORRANGE=FULL", "XCOLORRANGE given twice"},
    {"YUV4MPEG2 W4 H2 F25:1 Q7", "'Q7' is not a Y4M field"},
    {"YUV4MPEG2 W4  H2 F25:1", "empty field"},
    {"YUV4MPEG2 W4 H2 F25:1 ", "empty field"},
    {"YUV4MPEG2W4 H2 F25:1", "YUV4MPEG2 must be followed by a space"},
    {"YUV4MPEG2 W5 H2 F25:1", "W5 H2 C420jpeg: nv12 needs an even width, not 5"},
    {"YUV4MPEG2 W4 H3 F25:1", "W4 H3 C420jpeg: nv12 needs an even height, not 3"},
    {"YUV4MPEG2 W5 H3 F25:1 C422", "W5 H3 C422: yuyv needs an even width, not 5"},
    {"YUV4MPEG2 W20000 H2 F25:1", "W20000 H2 C420jpeg: size 20000x2 is over 16384"},
};

TEST(FileCameraErrors, EveryMalformedHeaderIsRefusedNamingTheField) {
  const test::ScratchDir dir;
  const std::filesystem::path path = dir / "take.y4m";
  for (const HeaderCase &c : kBadHeaders) {
    // A plausible frame after it, so that only the header can be at fault.
    test::write_text(path, std::string(c.header) + "\nFRAME\n" + std::string(12, '\x80'));
    EXPECT_EQ(open_error(path).rfind(path.string() + ": header: " + c.error, 0), 0u)
        << "header \"" << c.header << "\" gave: " << open_error(path);
  }
}

TEST(FileCameraErrors, AnUnknownRateIsFineWhenTheCallerGivesOne) {
  const test::ScratchDir dir;
  test::write_text(dir / "a.y4m", "YUV4MPEG2 W4 H2 F0:0\nFRAME\n" + std::string(12, 'x'));
  FileCameraOptions options;
  options.path = dir / "a.y4m";
  options.fps = 30;
  EXPECT_EQ(hal::camera::open_file_camera(options)->frame_interval_ns(), 33'333'333);
}

TEST(FileCameraErrors, HeaderWithoutItsEndOfLine) {
  const test::ScratchDir dir;
  const auto path = dir / "a.y4m";
  test::write_text(path, "YUV4MPEG2 W4 H2 F25:1");
  EXPECT_EQ(open_error(path),
            path.string() + ": header: the file ends before the header's end of line");
  test::write_text(path, "YUV4MPEG2 W4 H2 F25:1 X" + std::string(2000, 'a') + "\n");
  EXPECT_EQ(open_error(path), path.string() + ": header: no end of line in the first 1024 bytes");
}

TEST(FileCameraErrors, FirstFrameIsCheckedAtOpen) {
  const test::ScratchDir dir;
  const auto path = dir / "a.y4m";
  const std::string header = "YUV4MPEG2 W4 H2 F25:1\n";
  test::write_text(path, header);
  EXPECT_EQ(open_error(path), path.string() + ":frame 0: missing: the file has no frames");
  test::write_text(path, header + "FRAME\n" + "12345");
  EXPECT_EQ(open_error(path), path.string() + ":frame 0: truncated: 5 of 12 bytes");
  test::write_text(path, header + "FRAMX\n" + std::string(12, 'x'));
  EXPECT_EQ(open_error(path), path.string() + ":frame 0: garbled: 'FRAMX' where FRAME should be");
  test::write_text(path, header + "FRAMES\n" + std::string(12, 'x'));
  EXPECT_EQ(open_error(path), path.string() + ":frame 0: garbled: 'FRAMES' where FRAME should be");
  test::write_text(path, header + "FRAME");
  EXPECT_EQ(open_error(path),
            path.string() + ":frame 0: truncated: the FRAME line has no end of line");
  // 16384 x 16384 would want 400 MB a buffer: refused from the file's size.
  test::write_text(path, "YUV4MPEG2 W16384 H16384 F25:1\nFRAME\n" + std::string(100, 'x'));
  EXPECT_EQ(open_error(path), path.string() + ":frame 0: truncated: 100 of 402653184 bytes");
}

// The size the caller needs is checked against the header, before a frame
// of the file's size is read or allocated (a file that held all of a
// 16384 x 16384 frame's bytes would otherwise get its buffers first): the
// size is the error, not the truncation further on.
TEST(FileCameraErrors, ATakeOfAnotherSizeThanAskedIsRefusedFromItsHeader) {
  const test::ScratchDir dir;
  const auto path = dir / "a.y4m";
  test::write_text(path, "YUV4MPEG2 W16384 H16384 F25:1\nFRAME\n" + std::string(100, 'x'));
  FileCameraOptions options;
  options.path = path;
  options.width = 64;
  options.height = 48;
  try {
    (void)hal::camera::open_file_camera(options);
    FAIL() << "opened";
  } catch (const FileCameraError &e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": size: its frames are 16384x16384, the "
                                                     "camera's are to be 64x48");
  }
  test::write_text(path, "YUV4MPEG2 W64 H48 F25:1\nFRAME\n" + std::string(64 * 48 * 2, 'x'));
  EXPECT_NO_THROW((void)hal::camera::open_file_camera(options));
}

TEST(FileCameraErrors, WhatIsNotATakeAtAll) {
  const test::ScratchDir dir;
  EXPECT_EQ(open_error(dir / "none.y4m"),
            (dir / "none.y4m").string() + ": open: No such file or directory");
  test::write_text(dir / "notes.txt", "hello, world");
  EXPECT_EQ(open_error(dir / "notes.txt"),
            (dir / "notes.txt").string() + ": format: neither Y4M (YUV4MPEG2) nor PNG");
  test::write_text(dir / "a.y4m", "YUV4MPEG2 W4 H2 F25:1\nFRAME\n" + std::string(12, 'x'));
  for (const double fps : {-1.0, 0.001, 1e6, std::nan("")})
    EXPECT_EQ(open_error(dir / "a.y4m", fps).rfind((dir / "a.y4m").string() + ": fps: ", 0), 0u)
        << fps;
}

// Three 8x4 nv12 frames (48 bytes each) as the sink writes them.
std::string three_frames(const test::ScratchDir &dir) {
  const auto format = test::make_format(PixelFormat::nv12, 8, 4);
  auto sink = hal::output::open_y4m_sink(dir / "take.y4m", format, 25.0);
  test::write_all(*sink, {test::generated_frame(format, 0), test::generated_frame(format, 1),
                          test::generated_frame(format, 2)});
  return test::read_text(dir / "take.y4m");
}

// A take played once that breaks off has failed, naming the file and frame.
void expect_fails_after(hal::camera::CameraSource &camera, std::size_t frames,
                        const std::string &detail) {
  EXPECT_EQ(test::read_all(camera).size(), frames);
  CapturedFrame frame;
  EXPECT_EQ(camera.wait_frame(std::chrono::milliseconds(0), frame), CaptureResult::failed);
  const auto status = camera.status();
  EXPECT_FALSE(status.connected);
  EXPECT_EQ(status.frames, frames);
  EXPECT_EQ(status.errors, 1u);
  EXPECT_EQ(status.detail, detail);
}

// The three frames with the last cut 10 bytes short, played offline.
std::unique_ptr<hal::camera::CameraSource> cut_take(const test::ScratchDir &dir, bool loop) {
  const std::string file = three_frames(dir);
  test::write_text(dir / "take.y4m", file.substr(0, file.size() - 10));
  FileCameraOptions options;
  options.path = dir / "take.y4m";
  options.realtime = false;
  options.loop = loop;
  return hal::camera::open_file_camera(options);
}

TEST(FileCameraErrors, ATruncatedLastFrameFailsATakePlayedOnceNamingIt) {
  const test::ScratchDir dir;
  auto camera = cut_take(dir, false);
  expect_fails_after(*camera, 2,
                     (dir / "take.y4m").string() + ":frame 2: truncated: 38 of 48 bytes");
}

// A looping file stands in for a live camera: a frame it cannot read is a
// lost signal, named, and after kFileCameraRetryAfter it plays again from
// its first frame, for as long as the show goes on.
TEST(FileCameraErrors, ALoopingFileThatBreaksIsLostThenPlaysAgainFromItsFirstFrame) {
  const test::ScratchDir dir;
  const auto path = dir / "take.y4m";
  auto camera = cut_take(dir, true);
  const std::vector<std::vector<std::uint8_t>> first_pass = test::read_all(*camera);
  ASSERT_EQ(first_pass.size(), 2u);
  CapturedFrame frame;
  EXPECT_EQ(camera->wait_frame(std::chrono::milliseconds(0), frame), CaptureResult::disconnected);
  auto status = camera->status();
  EXPECT_FALSE(status.connected);
  EXPECT_EQ(status.errors, 1u);
  EXPECT_EQ(status.detail, path.string() + ":frame 2: truncated: 38 of 48 bytes; playing again "
                                           "from the first frame in 1000 ms");
  // Waiting out the retry: no frame before it, never past the timeout.
  const std::int64_t start = base::monotonic_ns();
  EXPECT_EQ(camera->wait_frame(std::chrono::milliseconds(100), frame), CaptureResult::disconnected);
  EXPECT_LT(base::monotonic_ns() - start, 900'000'000);
  EXPECT_EQ(test::read_all(*camera), first_pass) << "the same two frames again";
  status = camera->status();
  EXPECT_EQ(status.reconnects, 1u);
  EXPECT_EQ(status.errors, 2u) << "the second pass breaks at the same frame";
}

TEST(FileCameraErrors, AGarbledFrameFailsTheTakeNamingIt) {
  const test::ScratchDir dir;
  std::string file = three_frames(dir);
  const std::size_t second = file.find("FRAME\n", file.find("FRAME\n") + 1);
  ASSERT_NE(second, std::string::npos);
  file[second + 4] = 'X';
  const auto path = dir / "take.y4m";
  test::write_text(path, file);
  FileCameraOptions options;
  options.path = path;
  options.realtime = false;
  auto camera = hal::camera::open_file_camera(options);
  expect_fails_after(*camera, 1,
                     path.string() + ":frame 1: garbled: 'FRAMX' where FRAME should be");
}

} // namespace
} // namespace camhead
