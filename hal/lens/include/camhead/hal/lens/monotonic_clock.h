// The clock every lens reading is stamped on (EncoderReading::t_ns) and that
// frames are matched against: CLOCK_MONOTONIC, which never jumps with NTP or
// a settimeofday, in nanoseconds. Any thread.
#pragma once

#include <cstdint>
#include <ctime>

namespace camhead::hal::lens {

[[nodiscard]] inline std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

} // namespace camhead::hal::lens
