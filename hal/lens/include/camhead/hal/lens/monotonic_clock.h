// The clock every lens reading is stamped on (EncoderReading::t_ns) and that
// frames are matched against: base's CLOCK_MONOTONIC in nanoseconds.
#pragma once

#include "camhead/base/monotonic_clock.h"

namespace camhead::hal::lens {

using base::monotonic_ns;

} // namespace camhead::hal::lens
