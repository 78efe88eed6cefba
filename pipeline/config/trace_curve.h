// One axis of a recorded lens trace as a function of time: what the
// simulated USB board and GPIO chip latch, and what the simulated camera's
// lens truly is (run/trace_lens.h). Counts are linear between rows; with a
// period the trace repeats, the step from its last row back to its first
// interpolated like any other; without one the ends hold.
//
// Thread safety: immutable after construction.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "camhead/hal/lens/lens_encoder.h"
#include "camhead/hal/lens/trace/lens_trace.h"

namespace camhead::pipeline {

class TraceCurve {
public:
  using Axis = std::optional<std::int32_t> hal::lens::EncoderReading::*;

  // The rows of `trace` that carry `axis`, at seconds from the trace's first
  // row. `period_s`: the loop's period (hal::lens::loop_period_ns, or the
  // span for a loop whose last row is its first); empty: no loop.
  TraceCurve(const hal::lens::LensTrace &trace, Axis axis, std::optional<double> period_s);

  [[nodiscard]] bool empty() const { return points_.empty(); }
  // The counts at `t` seconds of trace time; 0 for an axis the trace lacks.
  [[nodiscard]] double at(double t) const;

private:
  struct Point {
    double t, counts;
  };
  std::vector<Point> points_;
  std::optional<double> period_s_;
};

} // namespace camhead::pipeline
