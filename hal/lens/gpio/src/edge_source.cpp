// Default clock of an edge source: CLOCK_MONOTONIC, the clock of the kernel's
// GPIO event timestamps and of EncoderReading::t_ns.
#include "camhead/hal/lens/gpio/edge_source.h"

#include <ctime>
#include <thread>

namespace camhead::hal::lens::gpio {

std::int64_t EdgeSource::now_ns() const {
  return monotonic_ns();
}

void EdgeSource::sleep_for(std::chrono::nanoseconds duration) {
  if (duration.count() > 0) {
    std::this_thread::sleep_for(duration);
  }
}

} // namespace camhead::hal::lens::gpio
