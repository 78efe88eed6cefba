// Wiring of filter, timeline and profile per axis: see lens_tracker.h.
#include "camhead/lens_control/lens_tracker.h"

namespace camhead::lens_control {

LensTracker::LensTracker(LensProfile profile, LensTrackerConfig config)
    : profile_(std::move(profile)), focus_(config.focus), iris_(config.iris), zoom_(config.zoom) {}

void LensTracker::Axis::push(std::int64_t t_ns, std::int32_t counts) {
  const SpikeRejector::Released r = filter.push(t_ns, counts);
  for (int i = 0; i < r.count; ++i)
    timeline.push(r.samples[std::size_t(i)]);
}

void LensTracker::push(const EncoderSample &sample) {
  if (sample.focus)
    focus_.push(sample.t_ns, *sample.focus);
  if (sample.iris)
    iris_.push(sample.t_ns, *sample.iris);
  if (sample.zoom)
    zoom_.push(sample.t_ns, *sample.zoom);
}

LensState LensTracker::state_at(std::int64_t t_ns) const {
  return profile_.evaluate(
      LensCounts{focus_.timeline.at(t_ns), iris_.timeline.at(t_ns), zoom_.timeline.at(t_ns)});
}

} // namespace camhead::lens_control
