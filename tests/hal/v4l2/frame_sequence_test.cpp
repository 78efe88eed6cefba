// Driver sequence numbers to camhead frame numbers and drops
// (hal/camera/include/camhead/hal/camera/frame_sequence.h).
#include "camhead/hal/camera/frame_sequence.h"

#include <gtest/gtest.h>

namespace camhead::hal::camera {
namespace {

TEST(FrameSequence, ConsecutiveNumbersDropNothing) {
  FrameSequence tracker;
  for (std::uint32_t s = 100; s < 110; ++s) {
    const auto step = tracker.next(s);
    EXPECT_EQ(step.sequence, s - 100u);
    EXPECT_EQ(step.dropped, 0u);
  }
}

TEST(FrameSequence, GapsAreDroppedFramesAndKeptInTheNumbers) {
  FrameSequence tracker;
  EXPECT_EQ(tracker.next(7).sequence, 0u);
  const auto step = tracker.next(10); // 8 and 9 were made and never dequeued
  EXPECT_EQ(step.dropped, 2u);
  EXPECT_EQ(step.sequence, 3u);
  EXPECT_EQ(tracker.next(11).sequence, 4u);
}

TEST(FrameSequence, ACounterThatNeverMovesIsNotADrop) {
  // v4l2loopback's mmap writers leave every number 0.
  FrameSequence tracker;
  for (std::uint64_t i = 0; i < 5; ++i) {
    const auto step = tracker.next(0);
    EXPECT_EQ(step.sequence, i);
    EXPECT_EQ(step.dropped, 0u);
  }
}

TEST(FrameSequence, WrappingAt32BitsIsOneStep) {
  FrameSequence tracker;
  (void)tracker.next(0xffff'fffeu);
  EXPECT_EQ(tracker.next(0xffff'ffffu).dropped, 0u);
  const auto step = tracker.next(0);
  EXPECT_EQ(step.dropped, 0u);
  EXPECT_EQ(step.sequence, 2u);
  EXPECT_EQ(tracker.next(2).dropped, 1u);
}

TEST(FrameSequence, GoingBackIsARestartNotFourBillionDrops) {
  FrameSequence tracker;
  (void)tracker.next(500);
  const auto step = tracker.next(3);
  EXPECT_EQ(step.dropped, 0u);
  EXPECT_EQ(step.sequence, 1u);
}

TEST(FrameSequence, AReopenedStreamCountsOnWithoutAGap) {
  FrameSequence tracker;
  (void)tracker.next(40);
  (void)tracker.next(41);
  tracker.restart();
  const auto first = tracker.next(5); // the new stream's first frame
  EXPECT_EQ(first.sequence, 2u);
  EXPECT_EQ(first.dropped, 0u);
  EXPECT_EQ(tracker.next(7).dropped, 1u);
}

} // namespace
} // namespace camhead::hal::camera
