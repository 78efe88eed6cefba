// Wiring of filter, timeline and profile per axis: see lens_tracker.h.
#include "camhead/lens_control/lens_tracker.h"

#include <cmath>
#include <optional>

namespace camhead::lens_control {

LensTracker::LensTracker(LensProfile profile, LensTrackerConfig config)
    : profile_(std::move(profile)), focus_(config.focus), iris_(config.iris), zoom_(config.zoom),
      focus_diopters_(config.focus.timeline), iris_stops_(config.iris.timeline),
      log_focal_length_(config.zoom.timeline) {}

void LensTracker::Axis::push(std::int64_t t_ns, std::int32_t counts) {
  const SpikeRejector::Released r = filter.push(t_ns, counts);
  for (int i = 0; i < r.count; ++i)
    timeline.push(r.samples[std::size_t(i)]);
}

void LensTracker::push(const EncoderSample &sample) {
  // Which of counts and value an axis takes: lens_tracker.h.
  const bool counts_win = profile_.calibrated();
  const auto route = [&](const std::optional<std::int32_t> &counts, Axis &axis,
                         std::optional<double> value, AxisTimeline &values) {
    if (counts && (counts_win || !value))
      axis.push(sample.t_ns, *counts);
    else if (value && std::isfinite(*value))
      values.push(sample.t_ns, *value);
  };
  const auto diopters = [](std::optional<double> m) -> std::optional<double> {
    if (!m || !(*m > 0.0))
      return std::nullopt;
    return std::isinf(*m) ? 0.0 : 1.0 / *m;
  };
  const auto positive_log = [](std::optional<double> v, double scale) -> std::optional<double> {
    if (!v || !(*v > 0.0))
      return std::nullopt;
    return scale * std::log2(*v);
  };
  route(sample.focus, focus_, diopters(sample.focus_distance_m), focus_diopters_);
  route(sample.iris, iris_, positive_log(sample.f_number, 2.0), iris_stops_);
  route(sample.zoom, zoom_, positive_log(sample.focal_length_mm, std::log(2.0)), log_focal_length_);
}

LensState LensTracker::state_at(std::int64_t t_ns) const {
  return profile_.evaluate(
      LensCounts{focus_.timeline.at(t_ns), iris_.timeline.at(t_ns), zoom_.timeline.at(t_ns)},
      LensValues{focus_diopters_.at(t_ns), iris_stops_.at(t_ns), log_focal_length_.at(t_ns)});
}

} // namespace camhead::lens_control
