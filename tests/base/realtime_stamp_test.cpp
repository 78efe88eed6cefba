// Kernel stamps on CLOCK_REALTIME moved to CLOCK_MONOTONIC (realtime_stamp.h),
// with clocks the test drives: a thread preempted between two clock reads
// must not move the offset, and a realtime clock stepped while a datagram
// waits in its queue must not take its receipt outside what the receiver
// knows of it (after the queue was last seen empty, before it was read).
#include <cstdint>
#include <ctime>
#include <limits>
#include <vector>

#include "camhead/base/realtime_stamp.h"

#include <gtest/gtest.h>

namespace camhead::base {
namespace {

// Realtime runs this far ahead of monotonic; each read advances time by
// 25 ns, plus the pauses queued for particular reads (a preemption there).
constexpr std::int64_t kRealtimeAheadNs = 1'700'000'000'000'000'000;

struct Clocks {
  std::int64_t monotonic_ns = 5'000'000'000;
  std::vector<std::int64_t> pause_before_read_ns = {}; // by read, from the first
  int reads = 0;

  std::int64_t operator()(clockid_t clock) {
    if (reads < int(pause_before_read_ns.size()))
      monotonic_ns += pause_before_read_ns[std::size_t(reads)];
    ++reads;
    monotonic_ns += 25;
    return clock == CLOCK_REALTIME ? monotonic_ns + kRealtimeAheadNs : monotonic_ns;
  }
};

// How much later than the instant it describes a stamp moved by the pair
// lands, in ns: the clocks' true offset less the pair's. Never negative (a
// moved stamp is never early), and at most the pair's spread.
std::int64_t lateness(const ClockPair &pair) {
  return kRealtimeAheadNs - (pair.realtime_ns - pair.monotonic_ns);
}

TEST(RealtimeStamp, AnUntroubledReadingGivesTheOffsetToWithinItsBracket) {
  Clocks clocks;
  const ClockPair now = read_clock_pair(clocks);
  EXPECT_EQ(clocks.reads, 3) << "a tight first bracket is kept";
  ASSERT_TRUE(now.known());
  EXPECT_EQ(now.spread_ns, 50);
  EXPECT_GE(lateness(now), 0);
  EXPECT_LE(lateness(now), now.spread_ns);
}

TEST(RealtimeStamp, APreemptionBetweenTwoReadsDoesNotMoveTheOffset) {
  // 5 ms away between the monotonic read and the second realtime read of the
  // first bracket: read naively (monotonic, then realtime), the offset would
  // be 5 ms off, and a datagram's receipt 5 ms early.
  Clocks clocks{.pause_before_read_ns = {0, 0, 5'000'000}};
  const ClockPair now = read_clock_pair(clocks);
  EXPECT_EQ(clocks.reads, 6) << "the wide bracket is read again";
  EXPECT_EQ(now.spread_ns, 50);
  EXPECT_GE(lateness(now), 0);
  EXPECT_LE(lateness(now), now.spread_ns);
}

TEST(RealtimeStamp, ThreePreemptedBracketsKeepTheTightest) {
  Clocks clocks{.pause_before_read_ns = {0, 0, 3'000'000, 0, 1'000'000, 0, 0, 0, 2'000'000}};
  const ClockPair now = read_clock_pair(clocks);
  EXPECT_EQ(clocks.reads, 9);
  EXPECT_EQ(now.spread_ns, 1'000'050) << "the second bracket";
  EXPECT_GE(lateness(now), 0);
  EXPECT_LE(lateness(now), now.spread_ns);
}

// Every bracket preempted after its monotonic read: the realtime of that
// read lies anywhere in a wide bracket. Taken as the bracket's midpoint, a
// stamp would move half of it (here 0.5 ms) before its instant; taken as its
// first read, never before.
TEST(RealtimeStamp, ABracketPreemptedAfterItsMonotonicReadNeverMakesAStampEarly) {
  Clocks clocks{.pause_before_read_ns = {0, 0, 1'000'000, 0, 0, 1'000'000, 0, 0, 1'000'000}};
  const ClockPair now = read_clock_pair(clocks);
  EXPECT_EQ(clocks.reads, 9);
  EXPECT_EQ(now.spread_ns, 1'000'050);
  EXPECT_GE(lateness(now), 0);
  EXPECT_LE(lateness(now), 25) << "the bracket's first read was 25 ns before its monotonic one";
}

TEST(RealtimeStamp, AStampMovesToTheMonotonicInstantItDescribes) {
  Clocks clocks;
  const std::int64_t queue_empty = clocks.monotonic_ns;
  const std::int64_t sent = queue_empty + 1'000'000;
  const std::int64_t stamp = sent + 2'000 + kRealtimeAheadNs; // the kernel, 2 us on
  clocks.monotonic_ns = sent + 3'000'000;                     // read 3 ms after
  const std::int64_t read_at = clocks.monotonic_ns;
  const ClockPair pair = read_clock_pair(clocks);
  const std::int64_t receipt = receipt_ns(stamp, pair, queue_empty, read_at);
  EXPECT_GE(receipt, sent + 2'000) << "never early";
  EXPECT_LE(receipt, sent + 2'000 + pair.spread_ns) << "late by the bracket at most";
}

TEST(RealtimeStamp, ARealtimeStepWhileADatagramWaitsKeepsItsReceiptWhereItCanHaveBeen) {
  const std::int64_t queue_empty = 5'000'000'000, sent = queue_empty + 1'000'000;
  const std::int64_t stamp = sent + kRealtimeAheadNs;
  for (const std::int64_t step_ns :
       {std::int64_t{3'600'000'000'000}, -std::int64_t{60'000'000'000}}) {
    // NTP steps the realtime clock after the kernel stamped the datagram,
    // before it is read (at `read_at`).
    Clocks clocks{.monotonic_ns = sent + 2'000'000};
    const std::int64_t read_at = clocks.monotonic_ns;
    const ClockPair later = read_clock_pair([&](clockid_t clock) {
      const std::int64_t t = clocks(clock);
      return clock == CLOCK_REALTIME ? t + step_ns : t;
    });
    const std::int64_t receipt = receipt_ns(stamp, later, queue_empty, read_at);
    EXPECT_GE(receipt, queue_empty) << "step " << step_ns << " ns: not before the queue was empty";
    EXPECT_LE(receipt, read_at) << "step " << step_ns << " ns: not after it was read";
  }
}

TEST(RealtimeStamp, ARealtimeStepInsideEveryBracketIsNotAnOffset) {
  // The clock ran backwards between a bracket's two reads in every try: no
  // offset can be read, and the receipt is the latest it can have been.
  std::int64_t t = 1'000'000'000;
  int reads = 0;
  const ClockPair now = read_clock_pair([&](clockid_t clock) {
    t += 25;
    return clock == CLOCK_REALTIME && reads++ % 2 == 1 ? t - 1'000'000'000 : t;
  });
  EXPECT_FALSE(now.known());
  EXPECT_EQ(receipt_ns(t + 12345, now, 0, 777), 777);
}

} // namespace
} // namespace camhead::base
