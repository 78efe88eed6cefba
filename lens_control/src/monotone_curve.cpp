// PCHIP: see monotone_curve.h for why.
#include "camhead/lens_control/monotone_curve.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace camhead::lens_control {

MonotoneCurve::MonotoneCurve(std::vector<double> xs, std::vector<double> ys)
    : xs_(std::move(xs)), ys_(std::move(ys)) {
  const std::size_t n = xs_.size();
  if (n < 2 || ys_.size() != n)
    throw std::invalid_argument("MonotoneCurve: need at least two (x, y) pairs");
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(xs_[i]) || !std::isfinite(ys_[i]) || (i > 0 && !(xs_[i] > xs_[i - 1])))
      throw std::invalid_argument("MonotoneCurve: xs must be finite and strictly increasing");

  // Secant slopes of each interval.
  std::vector<double> h(n - 1), d(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    h[k] = xs_[k + 1] - xs_[k];
    d[k] = (ys_[k + 1] - ys_[k]) / h[k];
  }

  // Interior tangents: zero at a local extremum (so the curve does not
  // overshoot it), otherwise the weighted harmonic mean of the two secants,
  // which keeps (m_k/d_k, m_k+1/d_k) inside the Fritsch-Carlson monotonicity
  // region. End tangents: the end secant, which is inside the region too.
  tangents_.assign(n, 0.0);
  tangents_[0] = d[0];
  tangents_[n - 1] = d[n - 2];
  for (std::size_t k = 1; k + 1 < n; ++k) {
    if (d[k - 1] * d[k] <= 0.0)
      continue;
    const double w1 = 2.0 * h[k] + h[k - 1];
    const double w2 = h[k] + 2.0 * h[k - 1];
    tangents_[k] = (w1 + w2) / (w1 / d[k - 1] + w2 / d[k]);
  }
}

MonotoneCurve::Result MonotoneCurve::operator()(double x) const {
  if (!(x > xs_.front()))
    return {ys_.front(), x < xs_.front() || std::isnan(x)};
  if (!(x < xs_.back()))
    return {ys_.back(), x > xs_.back()};

  // Interval k with xs[k] <= x < xs[k+1].
  const auto it = std::upper_bound(xs_.begin(), xs_.end(), x);
  const std::size_t k = std::size_t(it - xs_.begin()) - 1;
  if (x == xs_[k])
    return {ys_[k], false}; // calibration points are reproduced exactly

  const double h = xs_[k + 1] - xs_[k];
  const double t = (x - xs_[k]) / h;
  const double t2 = t * t, t3 = t2 * t;
  const double h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
  const double h10 = t3 - 2.0 * t2 + t;
  const double h01 = -2.0 * t3 + 3.0 * t2;
  const double h11 = t3 - t2;
  const double y =
      h00 * ys_[k] + h10 * h * tangents_[k] + h01 * ys_[k + 1] + h11 * h * tangents_[k + 1];

  // The interpolant is mathematically inside [y_k, y_k+1]; rounding can put it
  // an ulp outside, which would break "never leaves the neighbours" that the
  // profile's callers rely on (a diopter of -1e-17 is a negative distance).
  const auto [lo, hi] = std::minmax(ys_[k], ys_[k + 1]);
  return {std::clamp(y, lo, hi), false};
}

} // namespace camhead::lens_control
