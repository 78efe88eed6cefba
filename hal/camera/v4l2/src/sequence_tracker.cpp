// See sequence_tracker.h.
#include "sequence_tracker.h"

namespace camhead::hal::camera {

SequenceTracker::Step SequenceTracker::next(std::uint32_t driver_sequence) {
  Step step;
  if (have_last_) {
    // Modulo 2^32, so that the driver's counter wrapping is one step.
    const std::uint32_t delta = driver_sequence - last_;
    if (delta != 0 && delta < 0x8000'0000u) {
      step.dropped = delta - 1;
      next_ += step.dropped;
    }
  }
  have_last_ = true;
  last_ = driver_sequence;
  step.sequence = next_++;
  return step;
}

} // namespace camhead::hal::camera
