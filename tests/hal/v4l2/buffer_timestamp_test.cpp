// A buffer's stamp on CLOCK_MONOTONIC, whatever clock the driver used
// (hal/camera/v4l2/src/buffer_timestamp.h).
#include <linux/videodev2.h>

#include "buffer_timestamp.h"

#include <gtest/gtest.h>

namespace camhead::hal::camera {
namespace {

constexpr std::int64_t kS = 1'000'000'000;
constexpr std::int64_t kMonoNow = 5000 * kS;            // an uptime
constexpr std::int64_t kRealNow = 1'767'000'000LL * kS; // a date
// Both clocks just after a dequeue, as read_clock_pair() reads them.
constexpr base::ClockPair kNow{kMonoNow, kRealNow, 50};

TEST(BufferTimestamp, MonotonicFlagIsTakenAsIs) {
  const BufferStamp stamp =
      buffer_stamp(V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE,
                   kMonoNow - 30'000'000, kNow);
  EXPECT_EQ(stamp.ns, kMonoNow - 30'000'000);
  EXPECT_EQ(stamp.mark, TimestampMark::start_of_exposure);
  EXPECT_EQ(stamp.clock, StampClock::monotonic);
}

TEST(BufferTimestamp, EndOfFrameIsTheDefaultSource) {
  const BufferStamp stamp = buffer_stamp(V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC, kMonoNow - 1000, kNow);
  EXPECT_EQ(stamp.mark, TimestampMark::end_of_frame);
}

TEST(BufferTimestamp, UnflaggedMonotonicValuesAreRecognised) {
  // v4l2loopback 0.12.7: ktime_get_ts64, no flag.
  const BufferStamp stamp = buffer_stamp(0, kMonoNow - 2 * kS, kNow);
  EXPECT_EQ(stamp.ns, kMonoNow - 2 * kS);
  EXPECT_EQ(stamp.clock, StampClock::judged_monotonic);
}

TEST(BufferTimestamp, WallClockValuesAreConverted) {
  const BufferStamp stamp = buffer_stamp(V4L2_BUF_FLAG_TIMESTAMP_COPY, kRealNow - 40'000'000, kNow);
  EXPECT_EQ(stamp.ns, kMonoNow - 40'000'000);
  EXPECT_EQ(stamp.clock, StampClock::converted_realtime);
}

// Where no offset between the clocks could be read (a realtime step inside
// every bracket), a wall-clock stamp cannot be moved, nor may a stamp near 0
// (a writer counting from its start) pass for one: it was converted by an
// offset of "now", into the future.
TEST(BufferTimestamp, WithoutAnOffsetNoStampIsTakenForAWallClockOne) {
  for (const std::int64_t stamp_ns : {kRealNow - 40'000'000, std::int64_t{500'000'000}}) {
    const BufferStamp stamp =
        buffer_stamp(V4L2_BUF_FLAG_TIMESTAMP_COPY, stamp_ns, base::ClockPair{kMonoNow});
    EXPECT_EQ(stamp.ns, kMonoNow) << stamp_ns;
    EXPECT_EQ(stamp.clock, StampClock::dequeue_time) << stamp_ns;
  }
}

TEST(BufferTimestamp, UnusableStampsBecomeTheDequeueTime) {
  for (const std::int64_t bad :
       {std::int64_t{0}, std::int64_t{-5}, kMonoNow - 100 * kS, kMonoNow + 60 * kS}) {
    const BufferStamp stamp = buffer_stamp(0, bad, kNow);
    EXPECT_EQ(stamp.ns, kMonoNow) << bad;
    EXPECT_EQ(stamp.mark, TimestampMark::end_of_frame) << bad;
    EXPECT_EQ(stamp.clock, StampClock::dequeue_time) << bad;
  }
  // Flagged monotonic but zero: not a stamp either.
  EXPECT_EQ(buffer_stamp(V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC, 0, kNow).clock,
            StampClock::dequeue_time);
}

TEST(BufferTimestamp, EveryClockHasWords) {
  for (const StampClock clock : {StampClock::monotonic, StampClock::judged_monotonic,
                                 StampClock::converted_realtime, StampClock::dequeue_time})
    EXPECT_NE(clock_text(clock), "?");
}

} // namespace
} // namespace camhead::hal::camera
