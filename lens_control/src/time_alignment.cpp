// Ring buffer of delay-corrected samples and interpolation at a frame time:
// see time_alignment.h.
#include "camhead/lens_control/time_alignment.h"

#include <algorithm>

namespace camhead::lens_control {

AxisTimeline::AxisTimeline(TimelineParams p) : p_(p), ring_(p.capacity) {}

bool AxisTimeline::push(TimedCounts s) {
  s.t_ns -= p_.delay_ns;
  return ring_.push(s);
}

std::optional<AxisReading> AxisTimeline::at(std::int64_t t_ns) const {
  const std::size_t n = ring_.size();
  if (n == 0)
    return std::nullopt;
  const TimedCounts &oldest = ring_[0];
  const TimedCounts &newest = ring_[n - 1];

  if (t_ns < oldest.t_ns)
    return AxisReading{oldest.counts, t_ns, false}; // older than the history holds

  if (t_ns >= newest.t_ns) {
    // Extrapolate: a frame's mid-exposure is usually later than the newest
    // sample that has arrived, by about the source's delay.
    const std::int64_t ahead = t_ns - newest.t_ns;
    const bool fresh = ahead <= p_.max_extrapolation_ns;
    double slope = 0.0; // counts per ns
    if (n >= 2) {
      const TimedCounts &prev = ring_[n - 2];
      // Only along a continuous stretch; across a dropout the slope is a guess.
      if (newest.t_ns - prev.t_ns <= p_.stale_after_ns)
        slope = (newest.counts - prev.counts) / double(newest.t_ns - prev.t_ns);
    }
    const double dt = double(std::min(ahead, p_.max_extrapolation_ns));
    return AxisReading{newest.counts + slope * dt, t_ns, fresh};
  }

  const std::size_t i = ring_.bracket(t_ns);
  const TimedCounts &a = ring_[i], &b = ring_[i + 1];
  const double u = double(t_ns - a.t_ns) / double(b.t_ns - a.t_ns);
  return AxisReading{a.counts + u * (b.counts - a.counts), t_ns,
                     b.t_ns - a.t_ns <= p_.stale_after_ns};
}

} // namespace camhead::lens_control
