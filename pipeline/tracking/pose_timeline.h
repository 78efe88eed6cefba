// A tracked camera's recent poses, and its pose at any instant: the pose
// twin of lens_control's AxisTimeline, with the same rules, so that a frame's
// pose and lens state describe the same mid-exposure alike.
//
// Each pose is stamped when it arrived; the source's delay moves it back to
// the instant it describes. Between two poses the position is interpolated
// linearly and the orientation spherically; past the newest, both go on
// along the last two poses for at most `max_extrapolation_ns`, then hold.
// What is held, extrapolated further, interpolated across a dropout or older
// than the history is not fresh.
//
// Storage is reserved once (capacity); push() and at() allocate nothing.
// Thread safety: none; the owner locks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "camera_pose.h"
#include "camhead/base/time_ring.h"

namespace camhead::pipeline {

struct PoseTimelineParams {
  std::int64_t delay_ns = 0;
  std::int64_t max_extrapolation_ns = 20'000'000;
  std::int64_t stale_after_ns = 50'000'000;
  // 4096 poses hold 34 s of a 120 Hz tracker, 82 s of a 50 Hz one.
  std::size_t capacity = 4096;
};

struct PoseAt {
  CameraPose pose;
  bool fresh = false;
  // The instant is earlier than every pose: `pose` is the oldest, held back
  // (what a source knew of that instant only later, if at all).
  bool before_first = false;
};

class PoseTimeline {
public:
  explicit PoseTimeline(PoseTimelineParams p = {});

  // Adds a pose stamped t_ns (before the delay correction). A pose not later
  // than the newest is ignored: returns false.
  bool push(std::int64_t t_ns, const CameraPose &pose);
  // The pose at physical instant t_ns; empty while there is none.
  [[nodiscard]] std::optional<PoseAt> at(std::int64_t t_ns) const;
  [[nodiscard]] std::size_t size() const { return ring_.size(); }
  // The newest pose's physical instant; 0 when empty.
  [[nodiscard]] std::int64_t newest_ns() const;

private:
  struct Timed {
    std::int64_t t_ns; // physical: stamped - delay
    CameraPose pose;
  };

  PoseTimelineParams p_;
  base::TimeRing<Timed> ring_;
};

} // namespace camhead::pipeline
