// Shape-preserving interpolation through calibration points: the piecewise
// cubic Hermite interpolant with Fritsch-Carlson tangents (PCHIP, as in
// Fritsch & Carlson 1980 and Fritsch & Butland 1984, the same rule as
// scipy.interpolate.PchipInterpolator apart from the end tangents).
//
// Why PCHIP and not a spline: a lens table is measured, and a cubic spline
// overshoots between points (a focus distance that runs past the next mark and
// back), which would make the rendered focus pump while the ring moves one
// way. PCHIP passes through every point, is monotone wherever the data are,
// and never leaves the range of the two neighbouring points.
#pragma once

#include <vector>

namespace camhead::lens_control {

class MonotoneCurve {
public:
  struct Result {
    double y = 0.0;
    bool clamped = false; // x was outside [front_x, back_x]; y is the end value
  };

  MonotoneCurve() = default;
  // xs strictly increasing, at least two points, all finite: callers validate
  // their input first (the profile loader does, with errors naming the field);
  // a violation here is a bug and throws std::invalid_argument.
  MonotoneCurve(std::vector<double> xs, std::vector<double> ys);

  // Returns ys[i] bit for bit at xs[i]; between points, a value within the
  // closed range of the two neighbours; outside, the nearest end value.
  [[nodiscard]] Result operator()(double x) const;

  [[nodiscard]] bool empty() const { return xs_.empty(); }
  [[nodiscard]] const std::vector<double> &xs() const { return xs_; }
  [[nodiscard]] const std::vector<double> &ys() const { return ys_; }

private:
  std::vector<double> xs_, ys_, tangents_;
};

} // namespace camhead::lens_control
