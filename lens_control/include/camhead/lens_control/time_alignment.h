// Time alignment of one encoder source to a camera frame.
//
// Lens data and frames come from different clocks' worth of pipelines: a
// frame is exposed over an interval, and an encoder sample is stamped when it
// reaches us, some fixed time after the ring was actually there (USB polling,
// a network lens-data hop, the encoder's own averaging). So each source keeps
// a short history of filtered samples, each moved back by the source's
// measured delay, and the lens state for a frame is read off that history at
// the middle of the exposure: the instant whose blur the renderer reproduces.
//
// Thread safety: none; the lens thread pushes and queries.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "camhead/base/time_ring.h"
#include "camhead/lens_control/lens_state.h"

namespace camhead::lens_control {

// The instant a frame's lens state should describe.
[[nodiscard]] constexpr std::int64_t mid_exposure_ns(std::int64_t frame_start_ns,
                                                     std::int64_t exposure_ns) {
  return frame_start_ns + exposure_ns / 2;
}

struct TimelineParams {
  // How much later than the physical instant a sample is stamped: a sample
  // stamped t describes the lens at t - delay_ns. Measure it per source.
  std::int64_t delay_ns = 0;
  // Past the newest sample, extrapolate along the last two samples at most
  // this far; further out the value stops there and is marked not fresh.
  std::int64_t max_extrapolation_ns = 20'000'000;
  // Two neighbouring samples further apart than this have a dropout between
  // them: interpolating across it is a guess, marked not fresh.
  std::int64_t stale_after_ns = 50'000'000;
  // History length. A frame asks for its mid-exposure, which is as old as
  // the pipeline's latency when it asks: 650 ms for a 720x576 frame on the
  // CPU reference of a 2-core machine, seconds in a sanitizer build or behind
  // a slow simulated camera. 8192 samples hold 8 s at 1 kHz and 80 s at
  // 100 Hz (128 KiB an axis); a frame older than that gets the oldest
  // sample, flagged not fresh.
  std::size_t capacity = 8192;
};

class AxisTimeline {
public:
  explicit AxisTimeline(TimelineParams p = {});

  // Adds a filtered sample (stamped on the source's clock, before the delay
  // correction). Samples not later than the newest are ignored: returns false.
  bool push(TimedCounts s);
  // Same for a reading; a convenience for EncoderFilter's output.
  bool push(std::int64_t t_ns, double counts) { return push(TimedCounts{t_ns, counts}); }

  // The axis at physical time t_ns: linear between the two samples around t,
  // bounded extrapolation after the newest, the oldest value (not fresh)
  // before the history. Empty before the first sample. The reading's t_ns is
  // the query time.
  [[nodiscard]] std::optional<AxisReading> at(std::int64_t t_ns) const;

  [[nodiscard]] std::size_t size() const { return ring_.size(); }
  [[nodiscard]] const TimelineParams &params() const { return p_; }

private:
  TimelineParams p_;
  base::TimeRing<TimedCounts> ring_; // times moved to physical time
};

} // namespace camhead::lens_control
