// The lens chain in one object: raw encoder samples in, the lens state at a
// frame's mid-exposure out.
//
//   EncoderSample -> per axis: EncoderFilter (spikes, One Euro, in counts)
//                 -> AxisTimeline (delay correction, history)
//   frame time    -> counts at mid-exposure -> LensProfile -> LensState
//
// Interpolating counts in time and mapping afterwards keeps the timeline
// independent of the profile, so a profile can be swapped without losing the
// history, and the nonlinear map is applied once per frame, not per sample.
//
// A source that sends an axis's physical value (EncoderSample's
// focus_distance_m, f_number, focal_length_mm: it was calibrated at the
// sender) has it kept on a timeline of its own, in the space the profile
// interpolates that quantity in (diopters, stops, ln mm), without the
// encoder filter (made for counts) and with the same delay. Where an axis
// comes both ways, the counts win when the profile is calibrated (camhead's
// own calibration of this lens, the one its renders are checked against),
// and the value wins with the uncalibrated fallback (whose nominal lens
// says nothing of this one). The state at a frame takes, per axis, the
// counts if it has any, else the value (LensProfile::evaluate).
//
// Thread safety: none. The pipeline's lens thread owns it; frames ask for
// their state through that thread (pipeline/ queues the request).
#pragma once

#include <cstdint>
#include <utility>

#include "camhead/lens_control/encoder_filter.h"
#include "camhead/lens_control/lens_profile.h"
#include "camhead/lens_control/lens_state.h"
#include "camhead/lens_control/time_alignment.h"

namespace camhead::lens_control {

struct AxisConfig {
  EncoderFilterParams filter;
  TimelineParams timeline;
};

struct LensTrackerConfig {
  AxisConfig focus, iris, zoom;
};

class LensTracker {
public:
  explicit LensTracker(LensProfile profile, LensTrackerConfig config = {});

  // Feeds one sample; axes it does not carry are left alone (a dropout
  // there shows up as staleness when the state is read).
  void push(const EncoderSample &sample);

  // The lens at physical time t_ns. Axes that never reported take the
  // profile's rest values, not fresh.
  [[nodiscard]] LensState state_at(std::int64_t t_ns) const;
  [[nodiscard]] LensState state_for_frame(std::int64_t frame_start_ns,
                                          std::int64_t exposure_ns) const {
    return state_at(mid_exposure_ns(frame_start_ns, exposure_ns));
  }

  [[nodiscard]] const LensProfile &profile() const { return profile_; }
  // Maps the history through `profile` from now on (a reloaded calibration):
  // the counts are kept, not states, so nothing is lost. Which of counts and
  // value an axis takes follows the new profile from the next sample on.
  void set_profile(LensProfile profile) { profile_ = std::move(profile); }

private:
  struct Axis {
    explicit Axis(const AxisConfig &c) : filter(c.filter), timeline(c.timeline) {}
    void push(std::int64_t t_ns, std::int32_t counts);
    EncoderFilter filter;
    AxisTimeline timeline;
  };

  LensProfile profile_;
  Axis focus_, iris_, zoom_;
  AxisTimeline focus_diopters_, iris_stops_, log_focal_length_; // values, not counts
};

} // namespace camhead::lens_control
