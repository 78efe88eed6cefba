#include "trace_lens.h"

#include <cmath>
#include <variant>

#include "lens_sources.h"

namespace camhead::pipeline {

namespace hl = hal::lens;

std::optional<TraceLens> TraceLens::of_board(const Board &board) {
  if (board.lens.sources.empty())
    return std::nullopt;
  const auto *trace = std::get_if<TraceSourceConfig>(&board.lens.sources.front().kind);
  if (trace == nullptr || !trace->monotonic_origin)
    return std::nullopt;
  return TraceLens(hl::read_lens_trace(trace->file), load_board_profile(board), *trace);
}

TraceLens::TraceLens(hl::LensTrace trace, lens_control::LensProfile profile,
                     const TraceSourceConfig &config)
    : trace_(std::move(trace)), profile_(std::move(profile)), speed_(config.speed),
      loop_(config.loop) {
  const auto &r = trace_.readings;
  if (r.size() > 1) {
    const std::int64_t span = r.back().t_ns - r.front().t_ns;
    period_ns_ = span + span / std::int64_t(r.size() - 1);
  }
}

std::optional<double> TraceLens::counts_at(std::optional<std::int32_t> hl::EncoderReading::*axis,
                                           std::int64_t trace_ns) const {
  const auto &r = trace_.readings;
  const std::int64_t t0 = r.front().t_ns;
  // The last reading with the axis at or before trace_ns, and the next one
  // (the first of the next loop after the last).
  const hl::EncoderReading *before = nullptr;
  const hl::EncoderReading *after = nullptr;
  std::int64_t after_t = 0;
  for (const hl::EncoderReading &reading : r) {
    if (!(reading.*axis))
      continue;
    const std::int64_t t = reading.t_ns - t0;
    if (t <= trace_ns) {
      before = &reading;
    } else {
      after = &reading;
      after_t = t;
      break;
    }
  }
  if (after == nullptr && loop_)
    for (const hl::EncoderReading &reading : r)
      if (reading.*axis) {
        after = &reading;
        after_t = reading.t_ns - t0 + period_ns_;
        break;
      }
  if (before == nullptr)
    return after != nullptr ? std::optional<double>(*(after->*axis)) : std::nullopt;
  if (after == nullptr)
    return double(*(before->*axis));
  const double a = double(*(before->*axis));
  const double b = double(*(after->*axis));
  const double u = double(trace_ns - (before->t_ns - t0)) / double(after_t - (before->t_ns - t0));
  return a + (b - a) * u;
}

lens_control::LensState TraceLens::state_at(std::int64_t t_ns) const {
  // The replay's clock: trace time = instant x speed, modulo the period.
  double trace = double(t_ns) * speed_;
  if (loop_ && period_ns_ > 0)
    trace = std::fmod(trace, double(period_ns_));
  const auto trace_ns = std::int64_t(std::llround(trace));
  lens_control::LensCounts counts;
  const auto axis = [&](std::optional<std::int32_t> hl::EncoderReading::*field)
      -> std::optional<lens_control::AxisReading> {
    const std::optional<double> c = counts_at(field, trace_ns);
    if (!c)
      return std::nullopt;
    return lens_control::AxisReading{*c, t_ns, true};
  };
  counts.focus = axis(&hl::EncoderReading::focus);
  counts.iris = axis(&hl::EncoderReading::iris);
  counts.zoom = axis(&hl::EncoderReading::zoom);
  return profile_.evaluate(counts);
}

} // namespace camhead::pipeline
