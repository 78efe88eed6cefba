// The simulated twin through LensEncoder: the shared session's parsing,
// clock mapping, loss and malformed accounting and reconnect state machine,
// driven step by step (SimulatedDrive::manual) so that every count and every
// timestamp is exact.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "camhead/hal/lens/usb/lens_ramp.h"
#include "camhead/hal/lens/usb/simulated_usb_lens.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

using namespace std::chrono_literals;

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kStart = 10'000 * kMs;
constexpr std::int64_t kPeriod = 2 * kMs; // 500 Hz
constexpr std::int64_t kLatency = 250'000;

struct Rig {
  explicit Rig(SimulatedUsbLensOptions options = {}, UsbLensConfig config = {})
      : board(std::make_shared<SimulatedUsbLensBoard>(std::move(options), kStart)),
        lens(open_simulated_usb_lens(board, config, SimulatedDrive::manual)) {}

  // Advance the board by `ms` and collect what poll() delivers.
  std::vector<EncoderReading> run_for(std::int64_t ms) {
    board->advance_to(board->now_ns() + ms * kMs);
    std::vector<EncoderReading> out;
    lens->poll(0ms, out);
    return out;
  }

  std::shared_ptr<SimulatedUsbLensBoard> board;
  std::unique_ptr<LensEncoder> lens;
};

// The ramp index of a reading, or -1.
std::int64_t index_of(const EncoderReading &r) {
  if (!r.focus || !r.iris || !r.zoom) {
    return -1;
  }
  const auto i = LensRamp{}.index_of(LensAxes{*r.focus, *r.iris, *r.zoom});
  return i ? static_cast<std::int64_t>(*i) : -1;
}

TEST(SimulatedUsbLens, NamesItselfAfterTheBoard) {
  Rig rig;
  EXPECT_EQ(rig.lens->name(), "simulated usb 1209:0001");
  UsbLensConfig config;
  config.serial = "SIM0001";
  EXPECT_EQ(usb_lens_name(config), "usb 1209:0001 serial SIM0001");
}

TEST(SimulatedUsbLens, AbsentAtStartWaitsThenConnects) {
  SimulatedUsbLensOptions options;
  options.plugged = false;
  Rig rig(options);
  EncoderStatus s = rig.lens->status();
  EXPECT_FALSE(s.connected);
  EXPECT_EQ(s.detail, "simulated usb 1209:0001: not connected, waiting");
  EXPECT_TRUE(rig.run_for(100).empty());

  rig.board->replug();
  s = rig.lens->status();
  EXPECT_TRUE(s.connected);
  EXPECT_EQ(s.reconnects, 0u); // a first connection is not a reconnect
  EXPECT_NE(s.detail.find("connected (simulated, serial SIM0001, firmware 1.0.0)"),
            std::string::npos)
      << s.detail;
  EXPECT_EQ(rig.run_for(100).size(), 50u);
}

TEST(SimulatedUsbLens, StreamsTheTrajectoryAtTheLatchTimes) {
  Rig rig;
  const std::vector<EncoderReading> readings = rig.run_for(1000);
  // Sample k is latched at k * 2 ms and arrives 0.25 ms later: 500 by 1 s.
  ASSERT_EQ(readings.size(), 500u);
  for (std::size_t k = 0; k < readings.size(); ++k) {
    EXPECT_EQ(index_of(readings[k]), static_cast<std::int64_t>(k));
    // With a constant delay the mapping is exact: latch time plus the delay
    // floor (which lens_control's per-source delay removes).
    EXPECT_EQ(readings[k].t_ns, kStart + static_cast<std::int64_t>(k) * kPeriod + kLatency) << k;
    EXPECT_FALSE(readings[k].focus_distance_m.has_value());
  }
  const EncoderStatus s = rig.lens->status();
  EXPECT_TRUE(s.connected);
  EXPECT_EQ(s.readings, 500u);
  EXPECT_EQ(s.lost, 0u);
  EXPECT_EQ(s.malformed, 0u);
  EXPECT_EQ(s.reconnects, 0u);
}

TEST(SimulatedUsbLens, DroppedReportsCountAsLost) {
  Rig rig;
  (void)rig.run_for(100); // 50 reports
  rig.board->drop_next(3);
  const std::vector<EncoderReading> readings = rig.run_for(100);
  ASSERT_EQ(readings.size(), 47u);
  EXPECT_EQ(index_of(readings.front()), 53); // 50, 51, 52 never arrived
  const EncoderStatus s = rig.lens->status();
  EXPECT_EQ(s.lost, 3u);
  EXPECT_EQ(s.malformed, 0u);
  EXPECT_EQ(rig.board->counters().dropped, 3u);
}

TEST(SimulatedUsbLens, CorruptReportsCountAsMalformedNotLost) {
  Rig rig;
  (void)rig.run_for(100);
  rig.board->corrupt_next(2);
  const std::vector<EncoderReading> readings = rig.run_for(100);
  EXPECT_EQ(readings.size(), 48u);
  const EncoderStatus s = rig.lens->status();
  EXPECT_EQ(s.malformed, 2u);
  EXPECT_EQ(s.lost, 0u); // their sequence gap is not counted twice
  EXPECT_EQ(s.readings + s.malformed + s.lost, rig.board->counters().latched);
  EXPECT_NE(s.detail.find("last problem: usb lens report:"), std::string::npos) << s.detail;
}

TEST(SimulatedUsbLens, LongRunOfCorruptionIsAllCaught) {
  Rig rig;
  rig.board->corrupt_next(kUsbLensReportSize * 8); // every bit position once
  const std::vector<EncoderReading> readings = rig.run_for(1000);
  EXPECT_EQ(readings.size(), 500u - kUsbLensReportSize * 8);
  EXPECT_EQ(rig.lens->status().malformed, kUsbLensReportSize * 8);
  for (const EncoderReading &r : readings) {
    EXPECT_GE(index_of(r), 0); // nothing corrupted slipped through
  }
}

TEST(SimulatedUsbLens, UnplugAndReplugReconnectsAndStartsOver) {
  SimulatedUsbLensOptions options;
  options.clock_start_us = 123'456'789; // power-up value of the board's clock
  Rig rig(options);
  ASSERT_EQ(rig.run_for(500).size(), 250u);

  rig.board->unplug();
  EncoderStatus s = rig.lens->status();
  EXPECT_FALSE(s.connected);
  EXPECT_EQ(s.detail, "simulated usb 1209:0001: device went away (simulated unplug), waiting");
  EXPECT_TRUE(rig.run_for(300).empty());

  const std::int64_t replugged = rig.board->now_ns();
  rig.board->replug();
  const std::vector<EncoderReading> after = rig.run_for(500);
  ASSERT_EQ(after.size(), 250u);
  for (std::size_t k = 0; k < after.size(); ++k) {
    // A bus-powered board restarts: sequence, trajectory and clock from zero,
    // and the clock mapping is estimated afresh.
    EXPECT_EQ(index_of(after[k]), static_cast<std::int64_t>(k));
    EXPECT_EQ(after[k].t_ns, replugged + static_cast<std::int64_t>(k) * kPeriod + kLatency);
  }
  s = rig.lens->status();
  EXPECT_TRUE(s.connected);
  EXPECT_EQ(s.reconnects, 1u);
  EXPECT_EQ(s.lost, 0u); // what was sent into the void is not loss
  EXPECT_EQ(s.malformed, 0u);
  EXPECT_EQ(s.readings, 500u);
}

TEST(SimulatedUsbLens, RepeatedUnplugsCountEachReconnect) {
  Rig rig;
  for (int i = 0; i < 3; ++i) {
    (void)rig.run_for(50);
    rig.board->unplug();
    rig.board->unplug(); // twice: still one departure
    (void)rig.run_for(50);
    rig.board->replug();
  }
  EXPECT_EQ(rig.lens->status().reconnects, 3u);
  EXPECT_TRUE(rig.lens->status().connected);
}

TEST(SimulatedUsbLens, DriftAndJitterAreMappedAway) {
  SimulatedUsbLensOptions options;
  options.clock_skew_ppm = -100.0;                  // a slow crystal
  options.jitter_ns = 800'000;                      // 0-0.8 ms on top of the 0.25 ms floor
  options.clock_start_us = 0xFFFFFFFFu - 4'000'000; // and a wrap 4 s in
  Rig rig(options);
  std::vector<EncoderReading> readings;
  for (int i = 0; i < 120; ++i) { // 12 s, polled every 100 ms
    const std::vector<EncoderReading> more = rig.run_for(100);
    readings.insert(readings.end(), more.begin(), more.end());
  }
  ASSERT_GT(readings.size(), 5900u);
  EXPECT_EQ(rig.lens->status().lost, 0u);
  double worst = 0.0;
  for (const EncoderReading &r : readings) {
    const std::int64_t k = index_of(r);
    ASSERT_GE(k, 0);
    if (k >= 1000) { // after 2 s
      const std::int64_t truth = kStart + k * kPeriod + kLatency;
      worst = std::max(worst, std::abs(static_cast<double>(r.t_ns - truth)));
    }
  }
  EXPECT_LT(worst, 30'000.0); // against 800 us of jitter
  for (std::size_t i = 1; i < readings.size(); ++i) {
    EXPECT_GT(readings[i].t_ns, readings[i - 1].t_ns) << i;
  }
}

TEST(SimulatedUsbLens, FaultedOrUnhomedAxesAreWithheld) {
  Rig rig;
  rig.board->set_status(kStatusAllHomed | kStatusZoomFault);
  std::vector<EncoderReading> readings = rig.run_for(10);
  ASSERT_FALSE(readings.empty());
  EXPECT_TRUE(readings.back().focus.has_value());
  EXPECT_TRUE(readings.back().iris.has_value());
  EXPECT_FALSE(readings.back().zoom.has_value());
  EXPECT_NE(rig.lens->status().detail.find("; zoom encoder fault"), std::string::npos);

  rig.board->set_status(kStatusIrisHomed | kStatusZoomHomed);
  readings = rig.run_for(10);
  ASSERT_FALSE(readings.empty());
  EXPECT_FALSE(readings.back().focus.has_value());
  EXPECT_NE(rig.lens->status().detail.find("; focus not homed"), std::string::npos);

  rig.board->set_status(0); // nothing usable: no reading at all, but the text says why
  EXPECT_TRUE(rig.run_for(10).empty());
  EXPECT_NE(rig.lens->status().detail.find("focus not homed, iris not homed, zoom not homed"),
            std::string::npos);

  rig.board->set_status(kStatusAllHomed);
  EXPECT_FALSE(rig.run_for(10).empty());
  EXPECT_EQ(rig.lens->status().detail.find("homed"), std::string::npos);
}

TEST(SimulatedUsbLens, HomingCanBeWaived) {
  SimulatedUsbLensOptions options;
  options.status = 0;
  options.axes = kAxisFocus; // a focus-only board without an index
  UsbLensConfig config;
  config.require_homed = false;
  Rig rig(options, config);
  const std::vector<EncoderReading> readings = rig.run_for(10);
  ASSERT_FALSE(readings.empty());
  EXPECT_TRUE(readings.back().focus.has_value());
  EXPECT_FALSE(readings.back().iris.has_value()); // not fitted
  EXPECT_FALSE(readings.back().zoom.has_value());
}

TEST(SimulatedUsbLens, FullQueueDropsTheOldestAsLost) {
  UsbLensConfig config;
  config.queue_capacity = 10;
  Rig rig({}, config);
  const std::vector<EncoderReading> readings = rig.run_for(200); // 100 reports, no poll between
  ASSERT_EQ(readings.size(), 10u);
  EXPECT_EQ(index_of(readings.front()), 90); // the newest ten
  EXPECT_EQ(rig.lens->status().lost, 90u);
}

TEST(SimulatedUsbLens, AnotherSerialIsNotOurs) {
  UsbLensConfig config;
  config.serial = "LE000042";
  Rig rig({}, config);
  const EncoderStatus s = rig.lens->status();
  EXPECT_FALSE(s.connected);
  EXPECT_EQ(s.detail,
            "simulated usb 1209:0001 serial LE000042: found only serial SIM0001, waiting");
  EXPECT_TRUE(rig.run_for(100).empty());
}

// Real time: the source's own thread moves the board; poll() waits for data
// but never longer than its timeout, plugged or not.
TEST(SimulatedUsbLens, RealTimePollNeverOverrunsItsTimeout) {
  SimulatedUsbLensOptions options;
  options.plugged = false;
  auto board = std::make_shared<SimulatedUsbLensBoard>(options);
  auto lens = open_simulated_usb_lens(board);
  std::vector<EncoderReading> out;
  for (int i = 0; i < 3; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    lens->poll(30ms, out);
    const auto waited = std::chrono::steady_clock::now() - t0;
    EXPECT_GE(waited, 29ms);
    EXPECT_LT(waited, 500ms); // generous: CI machines are shared
  }
  EXPECT_TRUE(out.empty());

  board->replug();
  const auto deadline = std::chrono::steady_clock::now() + 2s;
  while (out.size() < 50 && std::chrono::steady_clock::now() < deadline) {
    lens->poll(100ms, out);
  }
  EXPECT_GE(out.size(), 50u);
  for (std::size_t i = 1; i < out.size(); ++i) {
    EXPECT_GT(out[i].t_ns, out[i - 1].t_ns);
  }
  EXPECT_TRUE(lens->status().connected);
}

} // namespace
} // namespace camhead::hal::lens
