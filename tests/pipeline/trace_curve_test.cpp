// One axis of a lens trace over time: linear between rows, held or looped
// at the ends as the trace's replay loops, rows without the axis skipped.
#include "camhead/hal/lens/trace/trace_replay.h"
#include "config/trace_curve.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

using hal::lens::EncoderReading;

hal::lens::LensTrace trace_of(std::initializer_list<std::pair<double, std::optional<int>>> rows) {
  hal::lens::LensTrace trace;
  for (const auto &[t_s, focus] : rows) {
    EncoderReading r;
    r.t_ns = std::int64_t(t_s * 1e9);
    r.focus = focus;
    r.iris = 7;
    trace.readings.push_back(r);
  }
  return trace;
}

TEST(TraceCurve, LinearBetweenRowsAndHeldAtTheEndsWithoutALoop) {
  const TraceCurve curve(trace_of({{0.0, 0}, {1.0, 100}, {2.0, 300}}), &EncoderReading::focus,
                         std::nullopt);
  EXPECT_DOUBLE_EQ(curve.at(0.5), 50.0);
  EXPECT_DOUBLE_EQ(curve.at(1.5), 200.0);
  EXPECT_DOUBLE_EQ(curve.at(-1.0), 0.0);
  EXPECT_DOUBLE_EQ(curve.at(9.0), 300.0);
}

TEST(TraceCurve, LoopsAsTheReplayDoesAcrossTheWrap) {
  const auto trace = trace_of({{0.0, 0}, {1.0, 100}, {2.0, 300}});
  const double period = double(hal::lens::loop_period_ns(trace)) * 1e-9;
  EXPECT_DOUBLE_EQ(period, 3.0) << "the span plus one mean interval";
  const TraceCurve curve(trace, &EncoderReading::focus, period);
  EXPECT_DOUBLE_EQ(curve.at(2.5), 150.0) << "from the last row back to the first";
  EXPECT_DOUBLE_EQ(curve.at(3.5), 50.0) << "the second loop";
}

TEST(TraceCurve, RowsWithoutTheAxisAreSkipped) {
  const auto trace = trace_of({{0.0, std::nullopt}, {1.0, 100}, {2.0, std::nullopt}, {3.0, 300}});
  const TraceCurve held(trace, &EncoderReading::focus, std::nullopt);
  EXPECT_DOUBLE_EQ(held.at(0.5), 100.0) << "before the axis's first row: its first value";
  EXPECT_DOUBLE_EQ(held.at(2.0), 200.0);
  const TraceCurve looped(trace, &EncoderReading::focus, 4.0);
  EXPECT_DOUBLE_EQ(looped.at(0.0), 200.0)
      << "half way from the last row (3 s) to the next first (5 s)";
  EXPECT_TRUE(TraceCurve(trace, &EncoderReading::zoom, 4.0).empty());
}

} // namespace
} // namespace camhead::pipeline
