#include "trace_lens.h"

#include <cmath>
#include <variant>
#include <vector>

#include "camhead/hal/lens/trace/trace_replay.h"
#include "camhead/lens_control/encoder_filter.h"
#include "config/lens_sources.h"

namespace camhead::pipeline {

namespace hl = hal::lens;

namespace {

// The replay's period when it loops (trace_replay.h), else none.
std::optional<double> period_of(const hl::LensTrace &trace, bool loop) {
  return loop ? std::optional<double>(double(hl::loop_period_ns(trace)) * 1e-9) : std::nullopt;
}

// The trace as the lens moved: each axis's lone glitches (a reading that
// leaves both of its neighbours, to the same side, by more than the lens
// chain's spike threshold: further than a ring travels between two readings
// and back) replaced by the mean of those neighbours. The encoder latched
// the glitch, and the simulated boards replay it as latched; the glass did
// not move, so the simulated camera must not film it.
hl::LensTrace as_the_lens_moved(hl::LensTrace trace) {
  const double travel = lens_control::EncoderFilterParams{}.spike_threshold_counts;
  for (auto axis :
       {&hl::EncoderReading::focus, &hl::EncoderReading::iris, &hl::EncoderReading::zoom}) {
    std::vector<hl::EncoderReading *> rows;
    for (hl::EncoderReading &r : trace.readings)
      if (r.*axis)
        rows.push_back(&r);
    // Judged on the readings as latched, not as already mended. The first
    // and last readings are kept as they are.
    std::vector<std::int32_t> latched;
    for (const hl::EncoderReading *r : rows)
      latched.push_back(*(r->*axis));
    for (std::size_t i = 1; i + 1 < rows.size(); ++i) {
      const double before = latched[i] - latched[i - 1], after = latched[i] - latched[i + 1];
      if (before * after > 0.0 && std::abs(before) > travel && std::abs(after) > travel)
        rows[i]->*axis = std::int32_t(std::lround(0.5 * (latched[i - 1] + latched[i + 1])));
    }
  }
  return trace;
}

} // namespace

std::optional<TraceLens> TraceLens::of_board(const Board &board) {
  if (board.lens.sources.empty())
    return std::nullopt;
  const auto *trace = std::get_if<TraceSourceConfig>(&board.lens.sources.front().kind);
  if (trace == nullptr || !trace->monotonic_origin)
    return std::nullopt;
  return TraceLens(as_the_lens_moved(hl::read_lens_trace(trace->file)), load_board_profile(board),
                   *trace);
}

TraceLens::TraceLens(const hl::LensTrace &trace, lens_control::LensProfile profile,
                     const TraceSourceConfig &config)
    : profile_(std::move(profile)), speed_(config.speed),
      loop_period_s_(period_of(trace, config.loop)),
      focus_(trace, &hl::EncoderReading::focus, period_of(trace, config.loop)),
      iris_(trace, &hl::EncoderReading::iris, period_of(trace, config.loop)),
      zoom_(trace, &hl::EncoderReading::zoom, period_of(trace, config.loop)) {
  if (loop_period_s_ && *loop_period_s_ > 0.0)
    *loop_period_s_ /= speed_;
  else
    loop_period_s_.reset();
}

lens_control::LensState TraceLens::state_at(std::int64_t t_ns) const {
  // The replay's clock, started at CLOCK_MONOTONIC 0: trace time is the
  // instant times the speed.
  const double trace_s = double(t_ns) * 1e-9 * speed_;
  const auto axis = [&](const TraceCurve &curve) -> std::optional<lens_control::AxisReading> {
    if (curve.empty())
      return std::nullopt;
    return lens_control::AxisReading{curve.at(trace_s), t_ns, true};
  };
  lens_control::LensCounts counts;
  counts.focus = axis(focus_);
  counts.iris = axis(iris_);
  counts.zoom = axis(zoom_);
  return profile_.evaluate(counts);
}

} // namespace camhead::pipeline
