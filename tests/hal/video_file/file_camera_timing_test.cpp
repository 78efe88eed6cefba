// The file camera's clock and buffers: looping continues the sequence,
// offline stamps step by exactly one interval, real-time playback keeps the
// rate without blocking past a timeout, and three buffers are all it lends.
#include <set>
#include <thread>
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
using hal::camera::FileCameraOptions;
using std::chrono::milliseconds;

const base::VideoFormat kFormat = test::make_format(PixelFormat::nv12, 8, 4);

// A two-frame take at 25 fps.
std::filesystem::path two_frames(const test::ScratchDir &dir) {
  auto sink = hal::output::open_y4m_sink(dir / "take.y4m", kFormat, 25.0);
  test::write_all(*sink, {test::generated_frame(kFormat, 0), test::generated_frame(kFormat, 1)});
  return dir / "take.y4m";
}

std::unique_ptr<hal::camera::CameraSource> open(const std::filesystem::path &path, bool loop,
                                                bool realtime, double fps = 0) {
  FileCameraOptions options;
  options.path = path;
  options.loop = loop;
  options.realtime = realtime;
  options.fps = fps;
  return hal::camera::open_file_camera(options);
}

std::int64_t elapsed_ms(std::int64_t since_ns) {
  return (base::monotonic_ns() - since_ns) / 1'000'000;
}

TEST(FileCameraTiming, LoopRestartsWithTheSequenceContinuing) {
  const test::ScratchDir dir;
  auto camera = open(two_frames(dir), true, false);
  CapturedFrame frame;
  for (std::uint64_t i = 0; i < 5; ++i) {
    ASSERT_EQ(camera->wait_frame(milliseconds(1000), frame), CaptureResult::frame);
    EXPECT_EQ(frame.sequence, i);
    EXPECT_EQ(std::vector<std::uint8_t>(frame.bytes.begin(), frame.bytes.end()),
              test::generated_frame(kFormat, static_cast<int>(i % 2)))
        << "frame " << i;
    camera->release(frame);
  }
  const auto status = camera->status();
  EXPECT_TRUE(status.connected);
  EXPECT_EQ(status.frames, 5u);
  EXPECT_NE(status.detail.find("loop 3"), std::string::npos) << status.detail;
}

TEST(FileCameraTiming, OfflineStampsStepByExactlyOneInterval) {
  const test::ScratchDir dir;
  const std::int64_t before = base::monotonic_ns();
  auto camera = open(two_frames(dir), true, false, 50.0);
  EXPECT_EQ(camera->frame_interval_ns(), 20'000'000);
  CapturedFrame frame;
  std::int64_t first = 0;
  for (std::int64_t i = 0; i < 7; ++i) {
    ASSERT_EQ(camera->wait_frame(milliseconds(1000), frame), CaptureResult::frame);
    if (i == 0) {
      first = frame.timestamp_ns;
      EXPECT_GE(first, before);
      EXPECT_LE(first, base::monotonic_ns());
    }
    EXPECT_EQ(frame.timestamp_ns, first + i * 20'000'000) << "frame " << i;
    EXPECT_EQ(frame.exposure_ns, 20'000'000);
    EXPECT_EQ(frame.mark, hal::camera::TimestampMark::start_of_exposure);
    EXPECT_EQ(hal::camera::mid_exposure_ns(frame), frame.timestamp_ns + 10'000'000);
    camera->release(frame);
  }
}

TEST(FileCameraTiming, TheFilesOwnRateIsTheDefault) {
  const test::ScratchDir dir;
  test::write_text(dir / "ntsc.y4m",
                   "YUV4MPEG2 W2 H2 F30000:1001 Ip\nFRAME\n" + std::string(6, 'x'));
  auto camera = open(dir / "ntsc.y4m", false, false);
  EXPECT_EQ(camera->frame_interval_ns(), 33'366'667);
}

TEST(FileCameraTiming, RealtimeKeepsTheRateAndNeverBlocksPastTheTimeout) {
  const test::ScratchDir dir;
  auto camera = open(two_frames(dir), true, true, 10.0); // 100 ms a frame
  CapturedFrame first, second;
  std::int64_t start = base::monotonic_ns();
  // The first frame once its exposure (a whole interval) is over, however
  // the wait is cut.
  EXPECT_EQ(camera->wait_frame(milliseconds(10), first), CaptureResult::timeout);
  ASSERT_EQ(camera->wait_frame(milliseconds(1000), first), CaptureResult::frame);
  EXPECT_GE(elapsed_ms(start), 99) << "the first frame is due one interval after the start";
  // Stamped when it was due, however late the camera's thread woke.
  EXPECT_GE(first.timestamp_ns, start + 100'000'000);
  EXPECT_LE(first.timestamp_ns, base::monotonic_ns());

  // Not due for 100 ms: a 10 ms wait comes back empty after about 10 ms.
  start = base::monotonic_ns();
  EXPECT_EQ(camera->wait_frame(milliseconds(10), second), CaptureResult::timeout);
  EXPECT_GE(elapsed_ms(start), 9);
  EXPECT_LT(elapsed_ms(start), 80);
  // Before the next call: a stall could make that call the one that
  // restarts the schedule.
  const std::int64_t asked = base::monotonic_ns();
  EXPECT_EQ(camera->wait_frame(milliseconds(0), second), CaptureResult::timeout);

  ASSERT_EQ(camera->wait_frame(milliseconds(1000), second), CaptureResult::frame);
  EXPECT_EQ(second.sequence, 1u);
  // Stamped on the schedule, however late the camera's thread woke: exactly
  // one interval apart. Only a call over a frame behind restarts the
  // schedule, from that call (the camera judges by its own clock, so the
  // test by the outcome).
  const std::int64_t apart = second.timestamp_ns - first.timestamp_ns;
  if (apart != 100'000'000) {
    EXPECT_GT(apart, 200'000'000) << "neither on the schedule nor restarted";
    EXPECT_GE(second.timestamp_ns, asked) << "the schedule restarts from the late call";
  }
  camera->release(first);
  camera->release(second);
}

// In real time a frame is handed over as its exposure ends, as a camera's
// is: its mid-exposure lies half a frame in the past, where the lens chain
// has readings, not half a frame in the future.
TEST(FileCameraTiming, RealtimeFramesAreStampedAtTheEndOfTheirExposure) {
  const test::ScratchDir dir;
  auto camera = open(two_frames(dir), true, true, 10.0); // 100 ms a frame
  CapturedFrame frame;
  ASSERT_EQ(camera->wait_frame(milliseconds(1000), frame), CaptureResult::frame);
  const std::int64_t now = base::monotonic_ns();
  EXPECT_EQ(frame.mark, hal::camera::TimestampMark::end_of_frame);
  EXPECT_EQ(frame.exposure_ns, 100'000'000);
  EXPECT_LE(frame.timestamp_ns, now);
  EXPECT_LE(hal::camera::mid_exposure_ns(frame), now - 50'000'000);
  camera->release(frame);
}

TEST(FileCameraTiming, ThreeBuffersAndNoFourth) {
  const test::ScratchDir dir;
  auto camera = open(two_frames(dir), true, false);
  CapturedFrame held[3];
  std::set<int> buffers;
  for (auto &frame : held) {
    ASSERT_EQ(camera->wait_frame(milliseconds(1000), frame), CaptureResult::frame);
    buffers.insert(frame.buffer);
  }
  EXPECT_EQ(buffers, (std::set<int>{0, 1, 2}));

  CapturedFrame fourth;
  const std::int64_t start = base::monotonic_ns();
  EXPECT_EQ(camera->wait_frame(milliseconds(20), fourth), CaptureResult::timeout);
  EXPECT_LT(elapsed_ms(start), 500);

  // Indexes that are not ours are ignored.
  for (const int foreign : {-1, 3, 7}) {
    CapturedFrame bogus = held[0];
    bogus.buffer = foreign;
    camera->release(bogus);
  }
  EXPECT_EQ(camera->wait_frame(milliseconds(0), fourth), CaptureResult::timeout);

  // One back, one more out, in that very buffer; the old frame's second
  // release must not free the new one.
  camera->release(held[0]);
  ASSERT_EQ(camera->wait_frame(milliseconds(1000), fourth), CaptureResult::frame);
  EXPECT_EQ(fourth.buffer, held[0].buffer);
  EXPECT_EQ(fourth.sequence, 3u);
  camera->release(held[0]);
  CapturedFrame fifth;
  EXPECT_EQ(camera->wait_frame(milliseconds(0), fifth), CaptureResult::timeout);
  EXPECT_EQ(camera->status().frames, 4u);

  // A release from another thread wakes a waiting capture thread.
  std::thread releaser([&] {
    std::this_thread::sleep_for(milliseconds(30));
    camera->release(held[1]);
  });
  ASSERT_EQ(camera->wait_frame(milliseconds(5000), fifth), CaptureResult::frame);
  releaser.join();
  EXPECT_EQ(fifth.buffer, held[1].buffer);
  EXPECT_EQ(fifth.sequence, 4u);
}

TEST(FileCameraTiming, EndedComesAtOnce) {
  const test::ScratchDir dir;
  auto camera = open(two_frames(dir), false, false);
  EXPECT_EQ(test::read_all(*camera).size(), 2u);
  CapturedFrame frame;
  const std::int64_t start = base::monotonic_ns();
  EXPECT_EQ(camera->wait_frame(milliseconds(1000), frame), CaptureResult::ended);
  EXPECT_EQ(camera->wait_frame(milliseconds(1000), frame), CaptureResult::ended);
  EXPECT_LT(elapsed_ms(start), 500);
  EXPECT_EQ(camera->status().errors, 0u);
}

} // namespace
} // namespace camhead
