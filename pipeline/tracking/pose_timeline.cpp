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

PoseTimeline::PoseTimeline(PoseTimelineParams p)
    : p_(p), ring_(std::max<std::size_t>(p.capacity, 2)) {}

bool PoseTimeline::push(std::int64_t t_ns, const CameraPose &pose) {
  const std::int64_t physical = t_ns - p_.delay_ns;
  if (size_ > 0 && physical <= sample(size_ - 1).t_ns)
    return false;
  if (size_ < ring_.size()) {
    ring_[(head_ + size_) % ring_.size()] = {physical, pose};
    ++size_;
  } else {
    ring_[head_] = {physical, pose};
    head_ = (head_ + 1) % ring_.size();
  }
  return true;
}

std::int64_t PoseTimeline::newest_ns() const {
  return size_ == 0 ? 0 : sample(size_ - 1).t_ns;
}

std::optional<PoseAt> PoseTimeline::at(std::int64_t t_ns) const {
  if (size_ == 0)
    return std::nullopt;
  const Timed &oldest = sample(0);
  const Timed &newest = sample(size_ - 1);
  if (t_ns < oldest.t_ns)
    return PoseAt{oldest.pose, false};
  if (t_ns >= newest.t_ns) {
    const std::int64_t ahead = t_ns - newest.t_ns;
    const bool fresh = ahead <= p_.max_extrapolation_ns;
    if (size_ < 2)
      return PoseAt{newest.pose, fresh};
    const Timed &prev = sample(size_ - 2);
    // Only along a continuous stretch; across a dropout the motion is a guess.
    if (newest.t_ns - prev.t_ns > p_.stale_after_ns)
      return PoseAt{newest.pose, fresh};
    const double dt = double(std::min(ahead, p_.max_extrapolation_ns));
    return PoseAt{between(prev.pose, newest.pose, 1.0 + dt / double(newest.t_ns - prev.t_ns)),
                  fresh};
  }
  std::size_t lo = 0, hi = size_ - 1; // sample(lo) <= t < sample(hi)
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    if (sample(mid).t_ns <= t_ns)
      lo = mid;
    else
      hi = mid;
  }
  const Timed &a = sample(lo), &b = sample(hi);
  const double u = double(t_ns - a.t_ns) / double(b.t_ns - a.t_ns);
  return PoseAt{between(a.pose, b.pose, u), b.t_ns - a.t_ns <= p_.stale_after_ns};
}

} // namespace camhead::pipeline
