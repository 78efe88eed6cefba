// The libgpiod backend itself (src/gpiod_edge_source.cpp, unchanged) against
// the fake kernel of fake_gpiod.h: line requests, events merged across the
// per-line queues, active-low index, the kernel's timestamps, and a chip that
// disappears and comes back. The same backend against the real gpio-sim
// driver runs in the QEMU hardware lab (tests/vm).
#include <chrono>
#include <ctime>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gpiod.h>

#include "camhead/hal/lens/gpio/gpio_quadrature.h"
#include "camhead/hal/lens/gpio/simulated_quadrature.h"
#include "fake_gpiod.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens::gpio {
namespace {

using namespace std::chrono_literals;
namespace fake = camhead::test::fake_gpiod;

constexpr const char *kChip = "fakechip0";
constexpr unsigned kFocusA = 1, kFocusB = 2, kFocusIndex = 3, kZoomA = 5, kZoomB = 6;

GpioQuadratureAxis lines(unsigned a, unsigned b, std::optional<unsigned> index = {}) {
  GpioQuadratureAxis axis;
  axis.line_a = a;
  axis.line_b = b;
  axis.line_index = index;
  return axis;
}

class GpiodBackend : public testing::Test {
protected:
  void SetUp() override {
    fake::reset();
    fake::add_chip(kChip, "camhead-test-chip", 8);
    config_.chip = kChip;
    config_.focus = lines(kFocusA, kFocusB, kFocusIndex);
    config_.focus->index_active_low = true;
    config_.zoom = lines(kZoomA, kZoomB);
    config_.bias = GpioBias::pull_up;
    config_.reopen_interval = 20ms;
    // Active-low index at rest: the physical line is high.
    fake::set_level(kChip, kFocusIndex, true, 0);
  }
  void TearDown() override { fake::reset(); }

  // Puts the edges of a simulated motion on the fake lines, at base + t.
  static void play(LensAxis axis, const SimulatedQuadratureAxis &motion, std::int64_t base_ns) {
    for (const EdgeEvent &e : quadrature_edges(axis, motion)) {
      unsigned offset = 0;
      bool level = e.level;
      if (axis == LensAxis::focus) {
        offset = e.line == QuadratureLine::a   ? kFocusA
                 : e.line == QuadratureLine::b ? kFocusB
                                               : kFocusIndex;
        level = e.line == QuadratureLine::index ? !e.level : e.level; // active low
      } else {
        offset = e.line == QuadratureLine::a ? kZoomA : kZoomB;
      }
      fake::set_level(kChip, offset, level, base_ns + e.t_ns);
    }
  }

  static SimulatedQuadratureAxis ramp(double from, double to, std::int64_t duration_ns) {
    SimulatedQuadratureAxis m;
    m.trajectory = {{0, from}, {duration_ns, to}};
    return m;
  }

  GpioQuadratureConfig config_;
};

TEST_F(GpiodBackend, RequestsEveryLineForBothEdges) {
  {
    auto encoder = open_gpio_quadrature(config_);
    EXPECT_EQ(encoder->name(), "gpio fakechip0");
    for (const unsigned offset : {kFocusA, kFocusB, kFocusIndex, kZoomA, kZoomB}) {
      const fake::LineInfo info = fake::line_info(kChip, offset);
      EXPECT_TRUE(info.requested) << "line " << offset;
      EXPECT_EQ(info.consumer, "camhead");
      EXPECT_TRUE(info.flags & GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP);
      EXPECT_EQ((info.flags & GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW) != 0, offset == kFocusIndex);
    }
    EXPECT_FALSE(fake::line_info(kChip, 0).requested);
    EXPECT_EQ(fake::open_handles(), 1);
    std::vector<EncoderReading> out;
    encoder->poll(0ms, out);
    ASSERT_EQ(out.size(), 1u); // the connect reading
    EXPECT_EQ(out[0].focus, 0);
    EXPECT_EQ(out[0].zoom, 0);
  }
  EXPECT_EQ(fake::open_handles(), 0); // RAII: the chip and its lines are released
  EXPECT_FALSE(fake::line_info(kChip, kFocusA).requested);
}

TEST_F(GpiodBackend, MergesThePerLineQueuesByTimestamp) {
  auto encoder = open_gpio_quadrature(config_);
  std::vector<EncoderReading> out;
  encoder->poll(0ms, out);
  // 24 focus steps and 12 zoom steps interleaved in time, all queued before
  // the next poll: each line's queue holds its own events only (<= 16), so
  // only the timestamps give the order A and B happened in.
  play(LensAxis::focus, ramp(0.0, 24.0, 24'000), 1'000'000);
  play(LensAxis::zoom, ramp(0.5, -11.5, 24'000), 1'000'000);
  out.clear();
  encoder->poll(10ms, out);
  ASSERT_EQ(out.size(), 1u); // one batch, one reading
  EXPECT_EQ(out[0].focus, 24);
  EXPECT_EQ(out[0].zoom, -12);
  EXPECT_EQ(out[0].t_ns, 1'000'000 + 24'000);
  EXPECT_EQ(encoder->status().missed_edges, 0u);
}

TEST_F(GpiodBackend, StartsFromTheLevelsItReads) {
  fake::set_level(kChip, kFocusA, true, 0);
  fake::set_level(kChip, kFocusB, true, 0); // count 2 of the cycle (AB = 11)
  auto encoder = open_gpio_quadrature(config_);
  SimulatedQuadratureAxis m = ramp(2.0, 5.0, 3000); // 11 -> 01 -> 00 -> 10
  play(LensAxis::focus, m, 10'000);
  std::vector<EncoderReading> out;
  encoder->poll(0ms, out);
  encoder->poll(10ms, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out.back().focus, 3);
  EXPECT_EQ(encoder->status().missed_edges, 0u);
}

TEST_F(GpiodBackend, ActiveLowGatedIndexHomes) {
  const AxisLevels gate = quadrature_levels(5, std::nullopt); // count 5: AB = 10
  ASSERT_TRUE(gate.a && !gate.b);
  config_.focus->decoder.counts_at_index = 100;
  config_.focus->decoder.index_gate = IndexGate::ab10;
  auto encoder = open_gpio_quadrature(config_);
  EXPECT_FALSE(encoder->homed(LensAxis::focus));
  SimulatedQuadratureAxis m = ramp(0.0, 10.0, 10'000);
  m.index_count = 5;
  play(LensAxis::focus, m, 10'000);
  std::vector<EncoderReading> out;
  encoder->poll(0ms, out);
  encoder->poll(10ms, out);
  EXPECT_TRUE(encoder->homed(LensAxis::focus));
  EXPECT_EQ(out.back().focus, 105);
}

TEST_F(GpiodBackend, WallClockStampsOfOldKernelsAreMapped) {
  auto encoder = open_gpio_quadrature(config_);
  timespec real{};
  clock_gettime(CLOCK_REALTIME, &real);
  const std::int64_t wall = real.tv_sec * 1'000'000'000LL + real.tv_nsec;
  fake::set_level(kChip, kZoomA, true, wall);
  std::vector<EncoderReading> out;
  encoder->poll(0ms, out);
  encoder->poll(10ms, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out.back().zoom, 1);
  EXPECT_NEAR(static_cast<double>(out.back().t_ns), static_cast<double>(monotonic_ns()), 1e8);
}

TEST_F(GpiodBackend, ChipRemovalDisconnectsAndReopens) {
  auto encoder = open_gpio_quadrature(config_);
  std::vector<EncoderReading> out;
  encoder->poll(0ms, out);
  play(LensAxis::zoom, ramp(0.0, 6.0, 6000), 1000);
  encoder->poll(10ms, out);
  ASSERT_EQ(out.back().zoom, 6);

  fake::remove_chip(kChip);
  EXPECT_NO_THROW(encoder->poll(10ms, out));
  EncoderStatus s = encoder->status();
  EXPECT_FALSE(s.connected);
  EXPECT_EQ(s.detail, "gpio fakechip0 line 1 (focus A): cannot read events: No such device; "
                      "reopening every 20 ms");
  EXPECT_EQ(fake::open_handles(), 0);

  // Still gone at the next attempt: the open error is reported instead.
  const auto give_up = std::chrono::steady_clock::now() + 2s;
  while (encoder->status().detail.find("cannot open chip") == std::string::npos &&
         std::chrono::steady_clock::now() < give_up) {
    EXPECT_NO_THROW(encoder->poll(10ms, out));
  }
  EXPECT_NE(encoder->status().detail.find("gpio fakechip0: cannot open chip: "), std::string::npos)
      << encoder->status().detail;

  fake::add_chip(kChip, "camhead-test-chip", 8);
  fake::set_level(kChip, kFocusIndex, true, 0);
  out.clear();
  while (!encoder->connected() && std::chrono::steady_clock::now() < give_up) {
    encoder->poll(10ms, out);
  }
  s = encoder->status();
  EXPECT_TRUE(s.connected) << s.detail;
  EXPECT_EQ(s.reconnects, 1u);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].zoom, 6); // counting carries on from before the gap
  EXPECT_TRUE(fake::line_info(kChip, kZoomB).requested);
}

TEST_F(GpiodBackend, BusyLineIsNamedWithItsConsumer) {
  fake::hold_line(kChip, kFocusB, "other-app");
  try {
    (void)open_gpio_quadrature(config_);
    FAIL() << "opened a line held by someone else";
  } catch (const std::runtime_error &e) {
    EXPECT_STREQ(e.what(), "gpio fakechip0 line 2 (focus B): cannot request both-edge events: "
                           "Device or resource busy; used by \"other-app\"");
  }
  EXPECT_EQ(fake::open_handles(), 0);
  EXPECT_FALSE(fake::line_info(kChip, kFocusA).requested); // released on the way out
}

TEST_F(GpiodBackend, LabelLookupNamesTheChipBothWays) {
  config_.chip = "camhead-test-chip";
  config_.zoom->line_b = 9;
  try {
    (void)open_gpio_quadrature(config_);
    FAIL() << "requested a line beyond the chip";
  } catch (const std::runtime_error &e) {
    EXPECT_STREQ(e.what(), "gpio camhead-test-chip (fakechip0) line 9 (zoom B): no such line; "
                           "the chip has 8 lines");
  }
}

} // namespace
} // namespace camhead::hal::lens::gpio
