// Device clock -> CLOCK_MONOTONIC: exact without jitter, within tens of
// microseconds with heavy one-sided jitter and crystal drift, continuous
// across the 32-bit wrap, and re-estimated after a reconnect or a jump.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "camhead/hal/lens/usb/device_clock.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kHostStart = 5'000 * kMs; // the host booted 5 s ago

// A board latching every 2 ms of host time, its clock `ppm` fast and
// starting at `device_start_us`; each report delayed by `floor_ns` plus
// whatever `extra` returns.
struct Stream {
  double ppm = 0.0;
  std::uint32_t device_start_us = 0;
  std::int64_t floor_ns = 150'000;
  std::int64_t period_ns = 2 * kMs;

  [[nodiscard]] std::int64_t latch(int k) const { return kHostStart + k * period_ns; }
  [[nodiscard]] std::uint32_t device(int k) const {
    const double us = static_cast<double>(k * period_ns) * (1.0 + ppm * 1e-6) / 1000.0;
    return device_start_us + static_cast<std::uint32_t>(std::llround(us));
  }
};

TEST(DeviceClockMapper, FirstReportMapsToItsReceiveTime) {
  DeviceClockMapper m;
  EXPECT_EQ(m.map(123, kHostStart + 777), kHostStart + 777);
}

TEST(DeviceClockMapper, ConstantDelayMapsToLatchPlusDelay) {
  const Stream s;
  DeviceClockMapper m;
  for (int k = 0; k < 3000; ++k) {
    const std::int64_t received = s.latch(k) + s.floor_ns;
    EXPECT_EQ(m.map(s.device(k), received), received) << k;
  }
}

TEST(DeviceClockMapper, FollowsTheFloorThroughJitterAndDrift) {
  Stream s;
  s.ppm = 80.0; // a fast crystal: 80 us per second
  std::mt19937_64 rng(42);
  std::exponential_distribution<double> queueing(1.0 / 400'000.0); // mean 0.4 ms
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  DeviceClockMapper m;
  std::int64_t previous = 0;
  double worst = 0.0;
  for (int k = 0; k < 10'000; ++k) { // 20 s at 500 Hz
    auto extra = static_cast<std::int64_t>(queueing(rng));
    if (unit(rng) < 0.01) {
      extra += 20 * kMs; // the host was busy
    }
    const std::int64_t received = s.latch(k) + s.floor_ns + extra;
    const std::int64_t t = m.map(s.device(k), received);
    EXPECT_LE(t, received) << k;
    EXPECT_GT(t, previous) << k;
    previous = t;
    if (k >= 1500) { // after 3 s
      worst = std::max(worst, std::abs(static_cast<double>(t - (s.latch(k) + s.floor_ns))));
    }
  }
  // Against +-0.4 ms of jitter and 20 ms spikes on the receive times.
  EXPECT_LT(worst, 40'000.0);
  EXPECT_NEAR(m.skew_ppm(), -80.0, 10.0); // the device clock runs fast
}

TEST(DeviceClockMapper, ContinuousAcrossTheDeviceClockWrap) {
  Stream s;
  s.device_start_us = 0xFFFFFFFFu - 1'500'000; // wraps 1.5 s in
  DeviceClockMapper m;
  std::int64_t previous = m.map(s.device(0), s.latch(0) + s.floor_ns);
  for (int k = 1; k < 2000; ++k) {
    const std::int64_t t = m.map(s.device(k), s.latch(k) + s.floor_ns);
    EXPECT_EQ(t - previous, s.period_ns) << k;
    previous = t;
  }
  EXPECT_GT(m.unwrapped_us(), std::int64_t{0xFFFFFFFF}); // it did wrap
  EXPECT_EQ(m.resyncs(), 0u);
}

TEST(DeviceClockMapper, ResetStartsTheEstimateOver) {
  Stream before;
  DeviceClockMapper m;
  for (int k = 0; k < 1000; ++k) {
    (void)m.map(before.device(k), before.latch(k) + before.floor_ns);
  }
  // The board was unplugged and powered up again: clock from 0, another
  // offset, and a longer delay floor on its new port.
  Stream after;
  after.floor_ns = 400'000;
  m.reset();
  const int shift = 5000; // 10 s later
  for (int k = 0; k < 1000; ++k) {
    const std::int64_t received = after.latch(k + shift) + after.floor_ns;
    const std::int64_t t = m.map(after.device(k), received);
    EXPECT_EQ(t, received) << k;
  }
}

TEST(DeviceClockMapper, JumpWithoutReconnectResyncs) {
  Stream s;
  DeviceClockMapper m;
  for (int k = 0; k < 1000; ++k) {
    (void)m.map(s.device(k), s.latch(k) + s.floor_ns);
  }
  // The firmware reset itself but USB stayed up: the clock restarts at 0.
  Stream restarted;
  ClockMapperParams defaults;
  for (int k = 1000; k < 2000; ++k) {
    const std::int64_t received = s.latch(k) + s.floor_ns;
    const std::int64_t t = m.map(restarted.device(k - 1000), received);
    EXPECT_LE(t, received);
    if (k >= 1000 + defaults.resync_after) {
      EXPECT_EQ(t, received) << k;
    }
  }
  EXPECT_EQ(m.resyncs(), 1u);
}

TEST(DeviceClockMapper, LateReportsAfterAHostStallKeepTheEstimate) {
  Stream s;
  DeviceClockMapper m;
  for (int k = 0; k < 1000; ++k) {
    (void)m.map(s.device(k), s.latch(k) + s.floor_ns);
  }
  // The host slept 1.5 s: the queued transfers complete late, all at once.
  for (int k = 1000; k < 1004; ++k) {
    const std::int64_t received = s.latch(1003) + 1500 * kMs;
    EXPECT_EQ(m.map(s.device(k), received), s.latch(k) + s.floor_ns) << k;
  }
  for (int k = 1004; k < 1100; ++k) {
    EXPECT_EQ(m.map(s.device(k), s.latch(k) + s.floor_ns), s.latch(k) + s.floor_ns);
  }
  EXPECT_EQ(m.resyncs(), 0u);
}

} // namespace
} // namespace camhead::hal::lens
