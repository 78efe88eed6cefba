#include "trace_lens.h"

#include <variant>

#include "camhead/hal/lens/trace/trace_replay.h"
#include "config/lens_sources.h"

namespace camhead::pipeline {

namespace hl = hal::lens;

namespace {

// The replay's period when it loops (trace_replay.h), else none.
std::optional<double> period_of(const hl::LensTrace &trace, bool loop) {
  return loop ? std::optional<double>(double(hl::loop_period_ns(trace)) * 1e-9) : std::nullopt;
}

} // namespace

std::optional<TraceLens> TraceLens::of_board(const Board &board) {
  if (board.lens.sources.empty())
    return std::nullopt;
  const auto *trace = std::get_if<TraceSourceConfig>(&board.lens.sources.front().kind);
  if (trace == nullptr || !trace->monotonic_origin)
    return std::nullopt;
  return TraceLens(hl::read_lens_trace(trace->file), load_board_profile(board), *trace);
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
