// The clock every frame and lens reading is stamped on: CLOCK_MONOTONIC, which
// never jumps with NTP or a settimeofday, in nanoseconds. V4L2's default
// buffer timestamps and libcamera's SensorTimestamp are on it too. Any thread.
#pragma once

#include <cstdint>
#include <ctime>

namespace camhead::base {

[[nodiscard]] inline std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

} // namespace camhead::base
