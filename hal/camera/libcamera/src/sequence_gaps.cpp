// See sequence_gaps.h.
#include "sequence_gaps.h"

namespace camhead::hal::camera::libcamera_settings {

SequenceGaps::Step SequenceGaps::next(std::uint32_t camera_sequence) {
  Step step;
  if (have_last_) {
    // Modulo 2^32, so that the counter wrapping is one step.
    const std::uint32_t delta = camera_sequence - last_;
    if (delta != 0 && delta < 0x8000'0000u) {
      step.dropped = delta - 1;
      next_ += step.dropped;
    }
  }
  have_last_ = true;
  last_ = camera_sequence;
  step.sequence = next_++;
  return step;
}

} // namespace camhead::hal::camera::libcamera_settings
