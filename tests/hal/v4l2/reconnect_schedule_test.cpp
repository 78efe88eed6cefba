// When a lost device is tried again (camhead/hal/v4l2/reconnect_schedule.h).
#include "camhead/hal/v4l2/reconnect_schedule.h"

#include <gtest/gtest.h>

namespace camhead::hal::v4l2 {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(ReconnectSchedule, NothingIsDueBeforeALoss) {
  const ReconnectSchedule schedule;
  EXPECT_FALSE(schedule.waiting());
  EXPECT_FALSE(schedule.due(0));
  EXPECT_FALSE(schedule.due(1'000'000 * kMs));
}

TEST(ReconnectSchedule, FirstTryAQuarterSecondAfterTheLoss) {
  ReconnectSchedule schedule;
  schedule.lost(1000 * kMs);
  EXPECT_TRUE(schedule.waiting());
  EXPECT_FALSE(schedule.due(1000 * kMs));
  EXPECT_FALSE(schedule.due(1249 * kMs));
  EXPECT_TRUE(schedule.due(1250 * kMs));
  EXPECT_EQ(schedule.next_ns(), 1250 * kMs);
}

TEST(ReconnectSchedule, FailedTriesRepeatEveryQuarterSecond) {
  ReconnectSchedule schedule;
  schedule.lost(0);
  std::int64_t t = 250 * kMs;
  for (int i = 1; i <= 5; ++i) {
    ASSERT_TRUE(schedule.due(t));
    schedule.failed(t);
    EXPECT_EQ(schedule.failures(), std::uint64_t(i));
    EXPECT_FALSE(schedule.due(t + 249 * kMs));
    t += 250 * kMs;
    EXPECT_TRUE(schedule.due(t));
  }
}

TEST(ReconnectSchedule, ALateTryDoesNotBringTheNextForward) {
  ReconnectSchedule schedule;
  schedule.lost(0);
  // The caller came back 3 s late: one try now, the next a quarter second
  // on, not twelve at once to make up.
  schedule.failed(3500 * kMs);
  EXPECT_FALSE(schedule.due(3600 * kMs));
  EXPECT_TRUE(schedule.due(3750 * kMs));
}

TEST(ReconnectSchedule, SuccessEndsTheWaitUntilTheNextLoss) {
  ReconnectSchedule schedule;
  schedule.lost(0);
  schedule.failed(500 * kMs);
  schedule.succeeded();
  EXPECT_FALSE(schedule.waiting());
  EXPECT_FALSE(schedule.due(10'000 * kMs));
  EXPECT_EQ(schedule.failures(), 0u);
  schedule.lost(20'000 * kMs);
  EXPECT_TRUE(schedule.due(20'250 * kMs));
}

TEST(ReconnectSchedule, IntervalIsConfigurable) {
  ReconnectSchedule schedule(100 * kMs);
  schedule.lost(0);
  EXPECT_TRUE(schedule.due(100 * kMs));
}

} // namespace
} // namespace camhead::hal::v4l2
