// PCHIP through calibration points: exact at the points, monotone where the
// data are, never outside the two neighbours, clamped outside the table.
#include <cmath>
#include <random>
#include <vector>

#include "camhead/lens_control/monotone_curve.h"

#include <gtest/gtest.h>

namespace camhead::lens_control {
namespace {

TEST(MonotoneCurve, ReproducesPointsBitForBit) {
  const std::vector<double> xs{-5, 0, 3, 10, 11, 40};
  const std::vector<double> ys{0.1, 0.2, 0.9, 1.0, 7.0, 7.5};
  const MonotoneCurve c(xs, ys);
  for (std::size_t i = 0; i < xs.size(); ++i) {
    EXPECT_EQ(c(xs[i]).y, ys[i]) << i;
    EXPECT_FALSE(c(xs[i]).clamped);
  }
}

TEST(MonotoneCurve, MonotoneOnDenseSweepOfIrregularData) {
  // Steep and flat stretches side by side: where a cubic spline overshoots.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> step(0.01, 50.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> xs{0}, ys{trial % 2 ? 100.0 : 0.0};
    const double dir = trial % 2 ? -1.0 : 1.0;
    for (int i = 0; i < 12; ++i) {
      xs.push_back(xs.back() + step(rng));
      ys.push_back(ys.back() + dir * step(rng) * (i % 3 == 0 ? 100.0 : 0.01));
    }
    const MonotoneCurve c(xs, ys);
    double prev = c(xs.front()).y;
    for (double x = xs.front(); x <= xs.back(); x += (xs.back() - xs.front()) / 20000.0) {
      const double y = c(x).y;
      EXPECT_GE(dir * (y - prev), 0.0) << "trial " << trial << " x " << x;
      prev = y;
    }
  }
}

TEST(MonotoneCurve, StaysBetweenNeighboursOnNonMonotoneData) {
  // Breathing tables need not be monotone; the curve must not overshoot.
  const std::vector<double> xs{0, 1, 2, 3, 4};
  const std::vector<double> ys{1, 3, 2, 2.5, 0};
  const MonotoneCurve c(xs, ys);
  for (double x = 0; x <= 4; x += 1e-3) {
    const std::size_t k = std::min<std::size_t>(std::size_t(x), 3);
    EXPECT_GE(c(x).y, std::min(ys[k], ys[k + 1])) << x;
    EXPECT_LE(c(x).y, std::max(ys[k], ys[k + 1])) << x;
  }
}

TEST(MonotoneCurve, ClampsOutsideAndFlagsIt) {
  const MonotoneCurve c({0, 10}, {5, 6});
  EXPECT_EQ(c(-1).y, 5);
  EXPECT_TRUE(c(-1).clamped);
  EXPECT_EQ(c(11).y, 6);
  EXPECT_TRUE(c(11).clamped);
  EXPECT_TRUE(c(std::nan("")).clamped);
  EXPECT_DOUBLE_EQ(c(5).y, 5.5); // two points: the straight line
}

TEST(MonotoneCurve, RejectsBadInputAsABug) {
  EXPECT_THROW(MonotoneCurve({0}, {1}), std::invalid_argument);
  EXPECT_THROW(MonotoneCurve({0, 0}, {1, 2}), std::invalid_argument);
  EXPECT_THROW(MonotoneCurve({0, 1}, {1, NAN}), std::invalid_argument);
}

} // namespace
} // namespace camhead::lens_control
