// Sequence-gap counting; see sequence_tracker.h.
#include "camhead/hal/lens/usb/sequence_tracker.h"

namespace camhead::hal::lens {

SequenceTracker::Step SequenceTracker::push(std::uint32_t sequence) {
  Step step;
  if (primed_) {
    // Unsigned subtraction is modular, so 0xFFFFFFFF -> 0 is a step of one
    // and a report repeated or older than the last comes out above 2^31.
    const std::uint32_t step_size = sequence - last_;
    if (step_size == 0 || step_size > kMaxPlausibleGap) {
      step.resync = true;
      ++resyncs_;
    } else {
      step.lost = step_size - 1;
      lost_ += step.lost;
    }
  }
  primed_ = true;
  last_ = sequence;
  return step;
}

} // namespace camhead::hal::lens
