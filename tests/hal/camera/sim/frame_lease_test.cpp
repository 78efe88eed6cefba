// A frame lease gives its buffer back exactly once, whichever way its holder
// lets go (frame_lease.h): the run loop drops frames on several paths, and a
// camera with a fixed number of buffers stalls on one kept, or is corrupted
// by one given back twice.
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "camhead/hal/camera/frame_lease.h"

#include <gtest/gtest.h>

namespace camhead::hal::camera {
namespace {

// Counts release() per buffer; delivers nothing itself.
class CountingCamera final : public CameraSource {
public:
  std::string name() const override { return "counting"; }
  base::VideoFormat format() const override { return {}; }
  std::int64_t frame_interval_ns() const override { return 0; }
  CaptureResult wait_frame(std::chrono::milliseconds, CapturedFrame &) override {
    return CaptureResult::timeout;
  }
  void release(const CapturedFrame &frame) override { ++released[frame.buffer]; }
  CameraStatus status() const override { return {}; }

  std::map<int, int> released;
};

CapturedFrame frame_in(int buffer) {
  CapturedFrame frame;
  frame.buffer = buffer;
  frame.sequence = std::uint64_t(buffer) + 100;
  return frame;
}

TEST(FrameLease, GivesTheBufferBackOnceWhicheverWayItIsLetGo) {
  CountingCamera camera;
  { const FrameLease dropped(camera, frame_in(0)); }
  EXPECT_EQ(camera.released, (std::map<int, int>{{0, 1}})) << "destroyed";

  FrameLease moved_from(camera, frame_in(1));
  FrameLease moved_to(std::move(moved_from));
  EXPECT_FALSE(moved_from);
  ASSERT_TRUE(moved_to);
  EXPECT_EQ(moved_to.frame().sequence, 101u);
  EXPECT_EQ(camera.released.count(1), 0u) << "a move gives nothing back";
  moved_to.reset();
  moved_to.reset();
  EXPECT_EQ(camera.released[1], 1) << "reset, twice";

  FrameLease held(camera, frame_in(2));
  held = FrameLease(camera, frame_in(3));
  EXPECT_EQ(camera.released[2], 1) << "assigned another frame";
  EXPECT_EQ(camera.released.count(3), 0u);

  // As in the run loop's queue: a frame replaced by a newer one goes back
  // when the optional that carried it out ends.
  std::optional<FrameLease> replaced(std::move(held));
  replaced.reset();
  EXPECT_EQ(camera.released[3], 1) << "dropped from a queue";
  EXPECT_EQ(camera.released.size(), 4u);
  for (const auto &[buffer, times] : camera.released)
    EXPECT_EQ(times, 1) << "buffer " << buffer;
}

} // namespace
} // namespace camhead::hal::camera
