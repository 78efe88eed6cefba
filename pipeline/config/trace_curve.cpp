#include "config/trace_curve.h"

#include <algorithm>
#include <cmath>

namespace camhead::pipeline {

TraceCurve::TraceCurve(const hal::lens::LensTrace &trace, Axis axis, std::optional<double> period_s)
    : period_s_(period_s) {
  for (const hal::lens::EncoderReading &r : trace.readings)
    if (r.*axis)
      points_.push_back({double(r.t_ns - trace.readings.front().t_ns) * 1e-9, double(*(r.*axis))});
  if (period_s_ && !(*period_s_ > 0.0))
    period_s_.reset(); // nothing to repeat
}

double TraceCurve::at(double t) const {
  if (points_.empty())
    return 0.0;
  if (points_.size() == 1)
    return points_.front().counts;
  t = std::max(t, 0.0);
  if (period_s_)
    t = std::fmod(t, *period_s_);
  const Point &first = points_.front();
  const Point &last = points_.back();
  if (t < first.t || t >= last.t) {
    // Before the first row of the axis or past its last: held, or across
    // the loop's wrap from the last row to the next loop's first.
    if (!period_s_ || *period_s_ + first.t <= last.t)
      return t < first.t ? first.counts : last.counts;
    const double after = t < first.t ? t + *period_s_ : t;
    const double next = first.t + *period_s_;
    return last.counts + (first.counts - last.counts) * (after - last.t) / (next - last.t);
  }
  const auto hi = std::upper_bound(points_.begin(), points_.end(), t,
                                   [](double v, const Point &p) { return v < p.t; });
  const Point &b = *hi, &a = *(hi - 1);
  return a.counts + (b.counts - a.counts) * (t - a.t) / (b.t - a.t);
}

} // namespace camhead::pipeline
