// Per-axis encoder filtering, in raw counts: a spike rejector, then a One Euro
// filter (Casiraghi, Roussel & Vogel, CHI 2012), then a still hold, then
// dropout detection.
//
// Why filter counts and not distances: the noise is in the counts (one count
// of quantisation, electrical noise, a missed quadrature edge). After the
// nonlinear profile map the same count of noise is a tiny distance change at
// the far end and a large one near the close-focus mark, so one set of filter
// parameters could not fit both ends. In counts it does.
//
// Why One Euro: a still lens wants a low cutoff (no visible jitter of the
// rendered focus), a moving lens wants a high one (no visible lag behind the
// plate). One Euro raises its cutoff with the filtered speed:
//   cutoff = min_cutoff_hz + beta * |d counts / dt|.
//
// Thread safety: none; one thread owns each filter (the lens thread).
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "camhead/lens_control/lens_state.h"

namespace camhead::lens_control {

struct OneEuroParams {
  double min_cutoff_hz = 1.0; // cutoff when still: sets the residual jitter
  double beta = 0.02;         // cutoff gain per count/s of speed: sets the lag when moving
  double d_cutoff_hz = 1.0;   // cutoff of the speed estimate itself
};

class OneEuroFilter {
public:
  explicit OneEuroFilter(OneEuroParams p = {}) : p_(p) {}
  // Returns the filtered value. The first sample passes unchanged; a sample
  // not later than the previous one (a clock glitch) is ignored and the
  // previous output returned.
  double filter(std::int64_t t_ns, double x);
  void reset() { primed_ = false; }

  // Smoothing factor of a first-order low-pass with this cutoff over dt.
  [[nodiscard]] static double alpha(double cutoff_hz, double dt_s);

private:
  OneEuroParams p_;
  bool primed_ = false;
  std::int64_t t_prev_ = 0;
  double x_prev_ = 0.0, dx_prev_ = 0.0;
};

// Drops single-sample glitches. A sample that jumps more than the threshold
// from the last good one is held back as a suspect until the next sample:
// if that one is back near the last good value, the suspect was a spike and is
// dropped; otherwise the lens really moved and the suspect is released, one
// sample late. Samples that move less than the threshold pass at once, so
// the extra latency is zero on slow moves and one sample on a step or on a
// move faster than threshold counts per sample. A glitch lasting two samples
// or more is indistinguishable from a move and passes.
class SpikeRejector {
public:
  struct Released {
    std::array<TimedCounts, 2> samples{};
    int count = 0; // 0 (holding a suspect), 1, or 2 (a confirmed suspect and this one)
  };

  explicit SpikeRejector(double threshold_counts) : threshold_(threshold_counts) {}
  [[nodiscard]] Released push(TimedCounts s);
  [[nodiscard]] std::uint64_t rejected() const { return rejected_; }
  void reset() {
    last_good_.reset();
    suspect_.reset();
  }

private:
  [[nodiscard]] bool near(const TimedCounts &a, const TimedCounts &b) const;

  double threshold_;
  std::optional<TimedCounts> last_good_, suspect_;
  std::uint64_t rejected_ = 0;
};

// Holds the filtered value exactly while it stays within `band` counts of
// the value last let through. A ring at rest then gives the renderer the same
// lens state frame after frame, so that its samples can add up
// (renderer/frame_history.h); the One Euro output alone creeps by fractions
// of a count for seconds after a move and jitters with encoder noise for
// ever. A move passes once it leaves the band, trailing it by at most `band`
// counts, and a ring that stops is reported within `band` counts of where
// the filter settles. A band of 0 holds nothing.
class StillHold {
public:
  explicit StillHold(double band_counts) : band_(band_counts) {}
  [[nodiscard]] double hold(double counts);

private:
  double band_;
  bool primed_ = false;
  double held_ = 0.0;
};

struct EncoderFilterParams {
  OneEuroParams one_euro;
  // StillHold's band: below the encoder's own resolution (1 count), above
  // most of the filtered noise (0.28 counts rms for 1-count Gaussian noise
  // on the raw counts, bench/RESULTS.md).
  double hold_counts = 1.0;
  double spike_threshold_counts = 64.0;
  // No sample for longer than this: the held value is reported stale.
  std::int64_t stale_after_ns = 50'000'000;
};

// Spike rejector, One Euro filter, still hold and dropout detection for one
// axis.
class EncoderFilter {
public:
  explicit EncoderFilter(EncoderFilterParams p = {})
      : p_(p), spikes_(p.spike_threshold_counts), smooth_(p.one_euro), still_(p.hold_counts) {}

  // Feeds one raw sample; returns the filtered samples it releases (0 to 2,
  // oldest first, at their own timestamps) for the time alignment.
  [[nodiscard]] SpikeRejector::Released push(std::int64_t t_ns, std::int32_t counts);

  // The latest filtered value as of `now_ns`: held through dropouts, marked
  // not fresh once no sample was released for stale_after_ns. Empty before
  // the first sample.
  [[nodiscard]] std::optional<AxisReading> current(std::int64_t now_ns) const;

  [[nodiscard]] std::uint64_t spikes_rejected() const { return spikes_.rejected(); }

private:
  EncoderFilterParams p_;
  SpikeRejector spikes_;
  OneEuroFilter smooth_;
  StillHold still_;
  std::optional<TimedCounts> last_;
};

} // namespace camhead::lens_control
