// A kernel stamp on CLOCK_REALTIME moved to CLOCK_MONOTONIC (monotonic_clock.h):
// a socket stamps a datagram's receipt only on realtime (SO_TIMESTAMPNS), as
// the GPIO character device did before Linux 5.7 and as some V4L2 drivers
// stamp their buffers.
//
// The stamp is moved across by the two clocks' offset, read once a batch of
// stamps (a drained socket queue, a GPIO wait's reads), after the first of
// them was taken: one offset keeps their order, and costs a few clock reads
// a batch, not a datagram. Read naively, one clock then the other, the
// offset is off by however long the thread was away between the two reads.
// Under load on a 2-core VM that put 10 loopback datagrams in a million up
// to 40 us before their own send, and once a tracker's first pose before
// the tracker had started (a CI failure). So the offset is read bracketed,
// realtime, monotonic, realtime, up to three times, and the tightest
// bracket is kept: none of 800,000 datagrams came before its send. The
// realtime of the monotonic read is taken as the bracket's first read, the
// earliest it can have been, so that a moved stamp is never early, and late
// by no more than the bracket (a midpoint could be early by half of it).
//
// And whatever the clocks do (a realtime step from NTP at a board's boot, a
// bracket preempted three times), receipt_ns keeps a stamp within the bounds
// its caller knows (for a datagram: not before its socket's queue was last
// seen empty, not after it was read).
//
// Header-only; read_clock_pair takes the clock to read, so that tests can
// drive it with their own. Any thread.
#pragma once

#include <algorithm>
#include <cstdint>
#include <ctime>
#include <limits>

namespace camhead::base {

// One instant on both clocks: realtime_ns is the earliest the realtime clock
// can have read at monotonic_ns; the truth is within spread_ns after it.
struct ClockPair {
  std::int64_t monotonic_ns = 0;
  std::int64_t realtime_ns = 0;
  std::int64_t spread_ns = std::numeric_limits<std::int64_t>::max();

  // Whether an offset was read (a realtime step inside every bracket: not).
  [[nodiscard]] bool known() const { return spread_ns != std::numeric_limits<std::int64_t>::max(); }
  // A realtime stamp moved by this pair's offset: never before the instant
  // it describes, and at most spread_ns after.
  [[nodiscard]] std::int64_t monotonic_of(std::int64_t stamp_realtime_ns) const {
    return stamp_realtime_ns + (monotonic_ns - realtime_ns);
  }
};

// A bracket this tight was not preempted: two clock reads take about 50 ns.
inline constexpr std::int64_t kTightBracketNs = 2'000;
inline constexpr int kBracketTries = 3;

// `read(clock)` reads a clock in nanoseconds (clock_gettime).
template <typename ReadClock> [[nodiscard]] ClockPair read_clock_pair(ReadClock &&read) {
  ClockPair best;
  for (int attempt = 0; attempt < kBracketTries && best.spread_ns > kTightBracketNs; ++attempt) {
    const std::int64_t before = read(CLOCK_REALTIME);
    const std::int64_t monotonic = read(CLOCK_MONOTONIC);
    const std::int64_t after = read(CLOCK_REALTIME);
    // A realtime clock that ran backwards was stepped: no offset to read there.
    if (after >= before && after - before < best.spread_ns) {
      best = {monotonic, before, after - before};
    }
  }
  if (!best.known()) {
    best.monotonic_ns = read(CLOCK_MONOTONIC); // the instant, without an offset
  }
  return best;
}

[[nodiscard]] inline std::int64_t read_clock_ns(clockid_t clock) {
  timespec ts{};
  ::clock_gettime(clock, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

[[nodiscard]] inline ClockPair read_clock_pair() {
  return read_clock_pair(read_clock_ns);
}

// The monotonic instant of a kernel stamp `stamp_realtime_ns` that was taken
// in [earliest_ns, latest_ns], moved by `clocks` (read after it): kept in
// those bounds, and `latest_ns` when no offset could be read.
[[nodiscard]] inline std::int64_t receipt_ns(std::int64_t stamp_realtime_ns,
                                             const ClockPair &clocks, std::int64_t earliest_ns,
                                             std::int64_t latest_ns) {
  if (!clocks.known()) {
    return latest_ns;
  }
  return std::clamp(clocks.monotonic_of(stamp_realtime_ns), std::min(earliest_ns, latest_ns),
                    latest_ns);
}

} // namespace camhead::base
