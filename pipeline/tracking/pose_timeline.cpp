#include "pose_timeline.h"

#include <algorithm>

#include <glm/gtc/quaternion.hpp>

namespace camhead::pipeline {
namespace {

// The pose a fraction u of the way from a to b; u > 1 goes on past b.
CameraPose between(const CameraPose &a, const CameraPose &b, double u) {
  // The nearer of the two quaternions that give b's orientation: the short
  // way round (glm's slerp picks it too, but not its linear fallback).
  const glm::dquat to =
      glm::dot(a.orientation, b.orientation) < 0.0 ? -b.orientation : b.orientation;
  return {a.position + u * (b.position - a.position),
          glm::normalize(glm::slerp(a.orientation, to, u))};
}

} // namespace

PoseTimeline::PoseTimeline(PoseTimelineParams p) : p_(p), ring_(p.capacity) {}

bool PoseTimeline::push(std::int64_t t_ns, const CameraPose &pose) {
  return ring_.push({t_ns - p_.delay_ns, pose});
}

std::int64_t PoseTimeline::newest_ns() const {
  return ring_.size() == 0 ? 0 : ring_[ring_.size() - 1].t_ns;
}

std::optional<PoseAt> PoseTimeline::at(std::int64_t t_ns) const {
  const std::size_t n = ring_.size();
  if (n == 0)
    return std::nullopt;
  const Timed &oldest = ring_[0];
  const Timed &newest = ring_[n - 1];
  if (t_ns < oldest.t_ns)
    return PoseAt{oldest.pose, false, true};
  if (t_ns >= newest.t_ns) {
    const std::int64_t ahead = t_ns - newest.t_ns;
    const bool fresh = ahead <= p_.max_extrapolation_ns;
    if (n < 2)
      return PoseAt{newest.pose, fresh};
    const Timed &prev = ring_[n - 2];
    // Only along a continuous stretch; across a dropout the motion is a guess.
    if (newest.t_ns - prev.t_ns > p_.stale_after_ns)
      return PoseAt{newest.pose, fresh};
    const double dt = double(std::min(ahead, p_.max_extrapolation_ns));
    return PoseAt{between(prev.pose, newest.pose, 1.0 + dt / double(newest.t_ns - prev.t_ns)),
                  fresh};
  }
  const std::size_t i = ring_.bracket(t_ns);
  const Timed &a = ring_[i], &b = ring_[i + 1];
  const double u = double(t_ns - a.t_ns) / double(b.t_ns - a.t_ns);
  return PoseAt{between(a.pose, b.pose, u), b.t_ns - a.t_ns <= p_.stale_after_ns};
}

} // namespace camhead::pipeline
