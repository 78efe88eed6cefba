// The lens a trace plays, at any instant: the physical truth of the
// simulated rig. The simulated camera films the real world through this
// lens, while the virtual objects get what the lens chain (encoder, filter,
// time alignment) makes of the same trace, as on a real rig; a chain that
// lags shows as a mismatch between real and virtual blur. An encoder's lone
// glitch in the trace (its bundled focus pull has one, at 3.0 s) is latched
// by the simulated boards but not followed by this lens: glass does not jump
// and come back within one reading.
//
// Only for a trace replayed with its time 0 at CLOCK_MONOTONIC 0 (board
// "clock_origin": "monotonic"): then the replay's reading i of loop k is due
// at (t_i - t_0 + k period) / speed, and this reads the same instant.
//
// Thread safety: immutable; any thread.
#pragma once

#include <cstdint>
#include <optional>

#include "camhead/lens_control/lens_profile.h"
#include "camhead/lens_control/lens_state.h"
#include "config/board.h"
#include "config/trace_curve.h"

namespace camhead::pipeline {

class TraceLens {
public:
  // The board's first lens source, when it is such a trace; else empty.
  // Throws as the trace and profile readers do.
  [[nodiscard]] static std::optional<TraceLens> of_board(const Board &board);

  // The lens at CLOCK_MONOTONIC instant t_ns: each axis's counts linear
  // between the readings around it (across a loop's wrap too; a lone glitch
  // replaced by the mean of its neighbours), through the profile.
  [[nodiscard]] lens_control::LensState state_at(std::int64_t t_ns) const;

  // How often the lens repeats, in seconds of real time, when the trace
  // loops; else empty.
  [[nodiscard]] std::optional<double> loop_period_s() const { return loop_period_s_; }

private:
  TraceLens(const hal::lens::LensTrace &trace, lens_control::LensProfile profile,
            const TraceSourceConfig &config);

  lens_control::LensProfile profile_;
  double speed_;
  std::optional<double> loop_period_s_;
  TraceCurve focus_, iris_, zoom_;
};

} // namespace camhead::pipeline
