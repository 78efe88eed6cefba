// Trace replay against an injected clock: readings leave at the right
// instants, poll waits for the next one but never past its timeout, looping
// and the speed factor. No test sleeps, except the one on the real clock.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "camhead/hal/lens/trace/trace_replay.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

using std::chrono::milliseconds;
constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kStart = 5'000 * kMs; // the fake clock's "now" at the first poll

// Time only moves when the replay sleeps (or the test says so).
class FakeClock final : public ReplayClock {
public:
  std::int64_t now = kStart;
  std::vector<std::int64_t> sleeps; // every sleep_until target, in order

  std::int64_t now_ns() override { return now; }
  void sleep_until(std::int64_t t_ns) override {
    sleeps.push_back(t_ns);
    now = std::max(now, t_ns);
  }
};

// Readings at 0, 10, 20, 50 ms of trace time (a 30 ms hole), focus = index.
LensTrace four_readings() {
  LensTrace t{"four.csv", {}};
  for (const std::int64_t ms : {0, 10, 20, 50}) {
    EncoderReading r;
    r.t_ns = ms * kMs;
    r.focus = static_cast<std::int32_t>(t.readings.size());
    r.f_stop = 2.8;
    t.readings.push_back(r);
  }
  return t;
}

TraceReplayOptions with(FakeClock &clock, bool loop = false, double speed = 1.0) {
  TraceReplayOptions o;
  o.clock = &clock;
  o.loop = loop;
  o.speed = speed;
  return o;
}

TEST(TraceReplay, FirstPollStartsThePlayAndDeliversTheFirstReading) {
  FakeClock clock;
  TraceReplay replay(four_readings(), with(clock));
  EXPECT_EQ(replay.name(), "trace four.csv");
  std::vector<EncoderReading> out;
  replay.poll(milliseconds(100), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].t_ns, kStart);
  EXPECT_EQ(out[0].focus, 0);
  EXPECT_EQ(out[0].f_stop, 2.8);
  EXPECT_TRUE(clock.sleeps.empty()) << "a due reading is returned without waiting";
}

TEST(TraceReplay, WaitsForTheNextReadingButNotPastTheTimeout) {
  FakeClock clock;
  TraceReplay replay(four_readings(), with(clock));
  std::vector<EncoderReading> out;
  replay.poll(milliseconds(100), out); // reading 0
  replay.poll(milliseconds(100), out); // sleeps to 10 ms, reading 1
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(clock.sleeps.back(), kStart + 10 * kMs);
  EXPECT_EQ(out[1].t_ns, kStart + 10 * kMs);

  replay.poll(milliseconds(4), out); // reading 2 is due at 20 ms: only 4 ms wait
  EXPECT_EQ(out.size(), 2u);
  EXPECT_EQ(clock.sleeps.back(), kStart + 14 * kMs);
  replay.poll(milliseconds(4), out);
  EXPECT_EQ(clock.now, kStart + 18 * kMs);
  replay.poll(milliseconds(4), out); // due at 20 <= 22: sleeps to 20, not 22
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(clock.now, kStart + 20 * kMs);
  EXPECT_EQ(out[2].t_ns, kStart + 20 * kMs);
}

TEST(TraceReplay, LateCallerGetsEverythingThatCameDueOldestFirst) {
  FakeClock clock;
  TraceReplay replay(four_readings(), with(clock));
  std::vector<EncoderReading> out;
  replay.poll(milliseconds(0), out);
  clock.now += 60 * kMs; // the lens thread was busy
  replay.poll(milliseconds(100), out);
  ASSERT_EQ(out.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(out[i].focus, static_cast<std::int32_t>(i));
  }
  EXPECT_EQ(out[3].t_ns, kStart + 50 * kMs) << "stamped when due, not when collected";
  EXPECT_EQ(clock.sleeps.size(), 0u);
}

TEST(TraceReplay, FinishedTraceWaitsOutTheTimeoutLikeASilentDevice) {
  FakeClock clock;
  TraceReplay replay(four_readings(), with(clock));
  std::vector<EncoderReading> out;
  clock.now += 1000 * kMs;
  replay.poll(milliseconds(0), out); // starts here, reading 0 only
  clock.now += 1000 * kMs;
  replay.poll(milliseconds(0), out);
  EXPECT_EQ(out.size(), 4u);
  EXPECT_TRUE(replay.finished());
  EXPECT_FALSE(replay.status().connected);
  EXPECT_EQ(replay.status().readings, 4u);
  EXPECT_NE(replay.status().detail.find("finished after 4 readings"), std::string::npos);

  const std::int64_t before = clock.now;
  replay.poll(milliseconds(25), out);
  EXPECT_EQ(out.size(), 4u);
  EXPECT_EQ(clock.now, before + 25 * kMs);
}

TEST(TraceReplay, LoopRepeatsAfterOneMeanInterval) {
  FakeClock clock;
  TraceReplay replay(four_readings(), with(clock, /*loop=*/true));
  // Span 50 ms over 3 intervals: the next loop starts 50 + 16 ms later
  // (integer nanoseconds: 16'666'666).
  const std::int64_t period = 50 * kMs + 50 * kMs / 3;
  EXPECT_EQ(replay.period_ns(), period);
  std::vector<EncoderReading> out;
  while (out.size() < 10) {
    replay.poll(milliseconds(100), out);
  }
  ASSERT_EQ(out.size(), 10u);
  const std::int64_t offsets_ms[] = {0, 10, 20, 50};
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::int64_t loop = static_cast<std::int64_t>(i / 4);
    EXPECT_EQ(out[i].t_ns, kStart + loop * period + offsets_ms[i % 4] * kMs) << "reading " << i;
    EXPECT_EQ(out[i].focus, static_cast<std::int32_t>(i % 4));
  }
  EXPECT_EQ(replay.loops_completed(), 2u);
  EXPECT_FALSE(replay.finished());
  EXPECT_TRUE(replay.status().connected);
}

TEST(TraceReplay, SpeedFactorScalesTheSchedule) {
  for (const double speed : {2.0, 0.5, 3.0}) {
    FakeClock clock;
    TraceReplay replay(four_readings(), with(clock, /*loop=*/false, speed));
    std::vector<EncoderReading> out;
    while (out.size() < 4) {
      replay.poll(milliseconds(1000), out);
    }
    const std::int64_t offsets_ms[] = {0, 10, 20, 50};
    for (std::size_t i = 0; i < 4; ++i) {
      EXPECT_EQ(out[i].t_ns, kStart + std::llround(offsets_ms[i] * kMs / speed))
          << "speed " << speed << ", reading " << i;
    }
  }
}

// A very long trace played slowly: its later readings fall past what int64
// nanoseconds hold. They are never due (once, the due time wrapped into the
// past, undefined behaviour, and every reading came at once).
TEST(TraceReplay, SlowPlayOfALongTraceDoesNotWrap) {
  LensTrace t{"long.csv", {}};
  for (const std::int64_t s : {std::int64_t(0), std::int64_t(1), std::int64_t(200'000'000)}) {
    EncoderReading r;
    r.t_ns = s * 1'000'000'000; // the last one 6 years in
    r.focus = static_cast<std::int32_t>(t.readings.size());
    t.readings.push_back(r);
  }
  FakeClock clock;
  TraceReplay replay(std::move(t), with(clock, /*loop=*/false, /*speed=*/0.01));
  std::vector<EncoderReading> out;
  replay.poll(milliseconds(10), out); // the first reading
  clock.now += 200'000 * kMs;         // past the second's 100 s
  replay.poll(milliseconds(10), out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].t_ns, kStart + 100'000 * kMs);
}

TEST(TraceReplay, TraceTimeNeedNotStartAtZero) {
  LensTrace t = four_readings();
  for (EncoderReading &r : t.readings) {
    r.t_ns += 7'000 * kMs;
  }
  FakeClock clock;
  TraceReplay replay(std::move(t), with(clock));
  std::vector<EncoderReading> out;
  replay.poll(milliseconds(100), out);
  replay.poll(milliseconds(100), out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].t_ns, kStart);
  EXPECT_EQ(out[1].t_ns, kStart + 10 * kMs);
}

TEST(TraceReplay, RejectsWhatCannotBePlayed) {
  FakeClock clock;
  EXPECT_THROW(TraceReplay(LensTrace{"empty.csv", {}}, with(clock)), TraceError);
  EXPECT_THROW(TraceReplay(four_readings(), with(clock, false, 0.0)), TraceError);
  EXPECT_THROW(TraceReplay(four_readings(), with(clock, false, -1.0)), TraceError);
  LensTrace single{"one.csv", {EncoderReading{}}};
  EXPECT_NO_THROW(TraceReplay(single, with(clock)));
  try {
    TraceReplay replay(single, with(clock, /*loop=*/true));
    FAIL() << "looped a trace without a time span";
  } catch (const TraceError &e) {
    EXPECT_EQ(std::string(e.what()), "one.csv: cannot loop a trace that spans no time");
  }
}

// The one test on CLOCK_MONOTONIC: poll returns, and a reading 20 ms ahead
// arrives within a generous bound.
TEST(TraceReplay, RealClockDeliversAndReturns) {
  LensTrace t = four_readings();
  t.readings.resize(2); // 0 and 10 ms
  TraceReplay replay(std::move(t));
  std::vector<EncoderReading> out;
  const auto start = std::chrono::steady_clock::now();
  while (out.size() < 2 && std::chrono::steady_clock::now() - start < std::chrono::seconds(5)) {
    replay.poll(milliseconds(100), out);
  }
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].t_ns - out[0].t_ns, 10 * kMs);
}

} // namespace
} // namespace camhead::hal::lens
