// The simulated camera behaves as a camera does for the code above it:
// exposures a frame interval apart, stamped at their start; no frame while
// every buffer is held; a frame it had no time for lost as a sequence gap;
// the disconnect fault reported and recovered from.
#include <chrono>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

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
