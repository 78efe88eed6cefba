// The simulated camera behaves as a camera does for the code above it:
// exposures a frame interval apart, stamped at their start; no frame while
// every buffer is held; a frame it had no time for lost as a sequence gap;
// the disconnect fault reported and recovered from; a warm-up that draws
// the loop first and a clock that keeps to its grid.
#include <chrono>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/camera/sim/simulated_camera.h"

#include <gtest/gtest.h>

namespace camhead::hal::camera {
namespace {

using namespace std::chrono_literals;

SimulatedCameraOptions small(bool realtime) {
  SimulatedCameraOptions o;
  o.format = {base::PixelFormat::yuyv, 16, 8};
  o.fps = 50.0;
  o.realtime = realtime;
  o.buffers = 2;
  return o;
}

// Writes the exposure's start into the frame, so the test can see what was
// drawn for which instant.
void stamp(std::int64_t start_ns, std::int64_t, std::span<std::uint8_t> out) {
  for (std::size_t i = 0; i < sizeof start_ns; ++i)
    out[i] = std::uint8_t(std::uint64_t(start_ns) >> (8 * i));
}

TEST(SimulatedCamera, OfflineFramesAreExactlyOneIntervalApart) {
  auto camera = open_simulated_camera(small(false), stamp);
  EXPECT_EQ(camera->frame_interval_ns(), 20'000'000);
  std::int64_t first = 0;
  for (std::uint64_t k = 0; k < 5; ++k) {
    CapturedFrame f;
    ASSERT_EQ(camera->wait_frame(100ms, f), CaptureResult::frame);
    if (k == 0)
      first = f.timestamp_ns;
    EXPECT_EQ(f.sequence, k);
    EXPECT_EQ(f.timestamp_ns, first + std::int64_t(k) * 20'000'000);
    EXPECT_EQ(f.mark, TimestampMark::start_of_exposure);
    EXPECT_EQ(f.exposure_ns, 10'000'000) << "a 180-degree shutter";
    EXPECT_EQ(mid_exposure_ns(f), f.timestamp_ns + 5'000'000);
    std::int64_t drawn = 0;
    for (std::size_t i = 0; i < sizeof drawn; ++i)
      drawn |= std::int64_t(f.bytes[i]) << (8 * i);
    EXPECT_EQ(drawn, f.timestamp_ns) << "the generator drew this frame's exposure";
    camera->release(f);
  }
}

TEST(SimulatedCamera, NoFrameWhileEveryBufferIsHeld) {
  auto camera = open_simulated_camera(small(false), stamp);
  CapturedFrame a, b, c;
  ASSERT_EQ(camera->wait_frame(100ms, a), CaptureResult::frame);
  ASSERT_EQ(camera->wait_frame(100ms, b), CaptureResult::frame);
  EXPECT_EQ(camera->wait_frame(10ms, c), CaptureResult::timeout);
  camera->release(a);
  EXPECT_EQ(camera->wait_frame(10ms, c), CaptureResult::frame);
}

TEST(SimulatedCamera, AFrameNobodyTookInTimeIsLost) {
  auto camera = open_simulated_camera(small(true), stamp);
  CapturedFrame f;
  ASSERT_EQ(camera->wait_frame(200ms, f), CaptureResult::frame);
  camera->release(f);
  std::this_thread::sleep_for(100ms); // five intervals with nobody taking frames
  ASSERT_EQ(camera->wait_frame(200ms, f), CaptureResult::frame);
  camera->release(f);
  EXPECT_GE(f.sequence, 4u);
  EXPECT_EQ(camera->status().dropped, f.sequence - 1) << "every gap counted";
}

TEST(SimulatedCamera, TheDisconnectFaultIsReportedAndRecoveredFrom) {
  SimulatedCameraOptions o = small(false);
  o.disconnect_after_frames = 2;
  o.disconnect_s = 0.1;
  auto camera = open_simulated_camera(o, stamp);
  CapturedFrame f;
  for (int k = 0; k < 2; ++k) {
    ASSERT_EQ(camera->wait_frame(100ms, f), CaptureResult::frame);
    camera->release(f);
  }
  EXPECT_EQ(camera->wait_frame(100ms, f), CaptureResult::disconnected);
  EXPECT_FALSE(camera->status().connected);
  EXPECT_NE(camera->status().detail.find("simulated disconnect"), std::string::npos);
  CaptureResult r = CaptureResult::disconnected;
  for (int tries = 0; tries < 50 && r != CaptureResult::frame; ++tries)
    r = camera->wait_frame(20ms, f);
  ASSERT_EQ(r, CaptureResult::frame);
  EXPECT_TRUE(camera->status().connected);
  EXPECT_EQ(camera->status().reconnects, 1u);
}

// Warm-up: the generator draws the loop's exposures as the camera opens,
// one interval apart, and every frame after it is an exposure of that
// grid, so that a generator keeping its pictures has each one at hand.
TEST(SimulatedCamera, AWarmUpDrawsTheLoopFirstAndTheFramesKeepToItsGrid) {
  std::vector<std::int64_t> drawn;
  std::vector<std::uint64_t> heard;
  SimulatedCameraOptions o = small(true);
  o.warm_up_frames = 4;
  o.warm_up_progress = [&](std::uint64_t n, std::uint64_t of) {
    EXPECT_EQ(of, 4u);
    heard.push_back(n);
  };
  auto camera = open_simulated_camera(
      o, [&](std::int64_t start, std::int64_t exposure, std::span<std::uint8_t> out) {
        drawn.push_back(start);
        stamp(start, exposure, out);
      });
  ASSERT_EQ(drawn.size(), 4u) << "drawn as the camera opened";
  const std::vector<std::int64_t> warm_up = drawn;
  EXPECT_EQ(heard, (std::vector<std::uint64_t>{1, 2, 3, 4}));
  for (std::size_t k = 1; k < warm_up.size(); ++k)
    EXPECT_EQ(warm_up[k] - warm_up[k - 1], 20'000'000);
  std::this_thread::sleep_for(33ms); // off the grid, as a pipeline's set-up is
  const std::int64_t asked = base::monotonic_ns();
  for (int k = 0; k < 3; ++k) {
    CapturedFrame f;
    ASSERT_EQ(camera->wait_frame(200ms, f), CaptureResult::frame);
    EXPECT_EQ((f.timestamp_ns - warm_up.front()) % 20'000'000, 0)
        << "frame " << k << " is " << (f.timestamp_ns - warm_up.front()) << " ns after the warm-up";
    EXPECT_GE(f.timestamp_ns, asked) << "the first exposure starts once the camera is asked";
    EXPECT_EQ(f.sequence, std::uint64_t(k));
    camera->release(f);
  }
}

TEST(SimulatedCamera, RefusesWhatNoCameraCouldBe) {
  SimulatedCameraOptions o = small(false);
  o.fps = 0.0;
  EXPECT_THROW((void)open_simulated_camera(o, stamp), std::invalid_argument);
  o = small(false);
  o.format.width = 15; // odd width in 4:2:2
  EXPECT_THROW((void)open_simulated_camera(o, stamp), std::invalid_argument);
  o = small(false);
  o.buffers = 1;
  EXPECT_THROW((void)open_simulated_camera(o, stamp), std::invalid_argument);
  EXPECT_THROW((void)open_simulated_camera(small(false), {}), std::invalid_argument);
}

} // namespace
} // namespace camhead::hal::camera
