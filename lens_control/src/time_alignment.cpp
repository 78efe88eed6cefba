// Ring buffer of delay-corrected samples and interpolation at a frame time:
// see time_alignment.h.
#include "camhead/lens_control/time_alignment.h"

#include <algorithm>

namespace camhead::lens_control {

AxisTimeline::AxisTimeline(TimelineParams p) : p_(p), ring_(std::max<std::size_t>(p.capacity, 2)) {}

bool AxisTimeline::push(TimedCounts s) {
  s.t_ns -= p_.delay_ns;
  if (size_ > 0 && s.t_ns <= sample(size_ - 1).t_ns)
    return false;
  if (size_ == ring_.size()) {
    ring_[head_] = s; // overwrite the oldest
    head_ = (head_ + 1) % ring_.size();
  } else {
    ring_[(head_ + size_) % ring_.size()] = s;
    ++size_;
  }
  return true;
}

std::optional<AxisReading> AxisTimeline::at(std::int64_t t_ns) const {
  if (size_ == 0)
    return std::nullopt;
  const TimedCounts &oldest = sample(0);
  const TimedCounts &newest = sample(size_ - 1);

  if (t_ns < oldest.t_ns)
    return AxisReading{oldest.counts, t_ns, false}; // older than the history holds

  if (t_ns >= newest.t_ns) {
    // Extrapolate: a frame's mid-exposure is usually later than the newest
    // sample that has arrived, by about the source's delay.
    const std::int64_t ahead = t_ns - newest.t_ns;
    const bool fresh = ahead <= p_.max_extrapolation_ns;
    double slope = 0.0; // counts per ns
    if (size_ >= 2) {
      const TimedCounts &prev = sample(size_ - 2);
      // Only along a continuous stretch; across a dropout the slope is a guess.
      if (newest.t_ns - prev.t_ns <= p_.stale_after_ns)
        slope = (newest.counts - prev.counts) / double(newest.t_ns - prev.t_ns);
    }
    const double dt = double(std::min(ahead, p_.max_extrapolation_ns));
    return AxisReading{newest.counts + slope * dt, t_ns, fresh};
  }

  // Binary search over the ring for the first sample later than t.
  std::size_t lo = 0, hi = size_ - 1; // sample(lo) <= t < sample(hi)
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    if (sample(mid).t_ns <= t_ns)
      lo = mid;
    else
      hi = mid;
  }
  const TimedCounts &a = sample(lo), &b = sample(hi);
  const double u = double(t_ns - a.t_ns) / double(b.t_ns - a.t_ns);
  return AxisReading{a.counts + u * (b.counts - a.counts), t_ns,
                     b.t_ns - a.t_ns <= p_.stale_after_ns};
}

} // namespace camhead::lens_control
