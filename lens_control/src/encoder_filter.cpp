// Spike rejection, One Euro filter, still hold and dropout detection: see
// encoder_filter.h.
#include "camhead/lens_control/encoder_filter.h"

#include <cmath>
#include <numbers>

namespace camhead::lens_control {

double OneEuroFilter::alpha(double cutoff_hz, double dt_s) {
  // Exponential smoothing equivalent of an RC low-pass: tau = 1 / (2 pi fc).
  const double r = 2.0 * std::numbers::pi * cutoff_hz * dt_s;
  return r / (r + 1.0);
}

double OneEuroFilter::filter(std::int64_t t_ns, double x) {
  if (!primed_) {
    primed_ = true;
    t_prev_ = t_ns;
    x_prev_ = x;
    dx_prev_ = 0.0;
    return x;
  }
  if (t_ns <= t_prev_)
    return x_prev_;
  // Real sample spacing rather than a nominal rate: USB and network encoders
  // deliver with jitter, and after a dropout dt is long and the filter should
  // catch up at once rather than glide from the old value.
  const double dt = double(t_ns - t_prev_) * 1e-9;
  const double dx = (x - x_prev_) / dt;
  const double dx_hat = dx_prev_ + alpha(p_.d_cutoff_hz, dt) * (dx - dx_prev_);
  const double cutoff = p_.min_cutoff_hz + p_.beta * std::abs(dx_hat);
  const double x_hat = x_prev_ + alpha(cutoff, dt) * (x - x_prev_);
  t_prev_ = t_ns;
  x_prev_ = x_hat;
  dx_prev_ = dx_hat;
  return x_hat;
}

bool SpikeRejector::near(const TimedCounts &a, const TimedCounts &b) const {
  return std::abs(a.counts - b.counts) <= threshold_;
}

SpikeRejector::Released SpikeRejector::push(TimedCounts s) {
  Released out;
  const auto release = [&out](const TimedCounts &c) { out.samples[std::size_t(out.count++)] = c; };
  if (!last_good_) {
    last_good_ = s;
    release(s);
    return out;
  }
  if (suspect_) {
    const TimedCounts suspect = *suspect_;
    suspect_.reset();
    if (near(s, *last_good_)) {
      // Out and straight back: a glitch. Drop it.
      ++rejected_;
      last_good_ = s;
      release(s);
      return out;
    }
    // The lens went somewhere and did not come back: the suspect was real.
    release(suspect);
    last_good_ = suspect;
  }
  if (!near(s, *last_good_)) {
    suspect_ = s;
    return out;
  }
  last_good_ = s;
  release(s);
  return out;
}

double StillHold::hold(double counts) {
  if (!primed_ || !(std::abs(counts - held_) <= band_)) {
    held_ = counts;
    primed_ = true;
  }
  return held_;
}

SpikeRejector::Released EncoderFilter::push(std::int64_t t_ns, std::int32_t counts) {
  SpikeRejector::Released r = spikes_.push({t_ns, double(counts)});
  for (int i = 0; i < r.count; ++i) {
    TimedCounts &c = r.samples[std::size_t(i)];
    c.counts = still_.hold(smooth_.filter(c.t_ns, c.counts));
    last_ = c;
  }
  return r;
}

std::optional<AxisReading> EncoderFilter::current(std::int64_t now_ns) const {
  if (!last_)
    return std::nullopt;
  return AxisReading{last_->counts, last_->t_ns, now_ns - last_->t_ns <= p_.stale_after_ns};
}

} // namespace camhead::lens_control
