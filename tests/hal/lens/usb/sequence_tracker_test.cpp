// Sequence-gap counting: gaps, the 32-bit wrap, and board restarts that must
// not count as loss.
#include <cstdint>

#include "camhead/hal/lens/usb/sequence_tracker.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

TEST(SequenceTracker, ConsecutiveNumbersLoseNothing) {
  SequenceTracker t;
  for (std::uint32_t s = 100; s < 200; ++s) {
    const auto step = t.push(s);
    EXPECT_EQ(step.lost, 0u);
    EXPECT_FALSE(step.resync);
  }
  EXPECT_EQ(t.lost(), 0u);
  EXPECT_EQ(t.resyncs(), 0u);
}

TEST(SequenceTracker, FirstReportIsNeverLoss) {
  SequenceTracker t;
  EXPECT_EQ(t.push(123456).lost, 0u);
  EXPECT_EQ(t.lost(), 0u);
}

TEST(SequenceTracker, CountsGaps) {
  SequenceTracker t;
  (void)t.push(10);
  EXPECT_EQ(t.push(14).lost, 3u); // 11, 12, 13
  EXPECT_EQ(t.push(15).lost, 0u);
  EXPECT_EQ(t.push(17).lost, 1u);
  EXPECT_EQ(t.lost(), 4u);
}

TEST(SequenceTracker, WrapsAtTwoToTheThirtyTwo) {
  SequenceTracker t;
  (void)t.push(0xFFFFFFFE);
  EXPECT_EQ(t.push(0xFFFFFFFF).lost, 0u);
  EXPECT_EQ(t.push(0).lost, 0u);
  EXPECT_EQ(t.push(1).lost, 0u);
  (void)t.push(0xFFFFFFFD);
  EXPECT_EQ(t.resyncs(), 1u);    // a jump backwards
  EXPECT_EQ(t.push(2).lost, 4u); // FFFFFFFE, FFFFFFFF, 0, 1
  EXPECT_EQ(t.lost(), 4u);
}

TEST(SequenceTracker, BackwardsOrRepeatedIsARestartNotLoss) {
  SequenceTracker t;
  (void)t.push(5000);
  auto step = t.push(0); // the board restarted
  EXPECT_TRUE(step.resync);
  EXPECT_EQ(step.lost, 0u);
  EXPECT_EQ(t.push(1).lost, 0u);
  step = t.push(1); // repeated
  EXPECT_TRUE(step.resync);
  EXPECT_EQ(t.lost(), 0u);
  EXPECT_EQ(t.resyncs(), 2u);
}

TEST(SequenceTracker, ImplausiblyLargeJumpIsARestart) {
  SequenceTracker t;
  (void)t.push(0);
  EXPECT_EQ(t.push(SequenceTracker::kMaxPlausibleGap).lost,
            SequenceTracker::kMaxPlausibleGap - 1); // the largest gap still counted
  const auto step = t.push(SequenceTracker::kMaxPlausibleGap * 3);
  EXPECT_TRUE(step.resync);
  EXPECT_EQ(step.lost, 0u);
}

TEST(SequenceTracker, ResetForgetsThePreviousReport) {
  SequenceTracker t;
  (void)t.push(100);
  t.reset();
  const auto step = t.push(5); // after a reconnect: a first report again
  EXPECT_EQ(step.lost, 0u);
  EXPECT_FALSE(step.resync);
  EXPECT_EQ(t.push(6).lost, 0u);
}

} // namespace
} // namespace camhead::hal::lens
