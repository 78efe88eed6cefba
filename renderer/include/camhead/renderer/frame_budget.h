// Rays per pixel for a frame-time target: the budget a live frame spends,
// uniform or adaptive, for a frame-time target.
//
// The cost of a frame is a part that its rays per pixel do not change (the
// camera frame in and the composite out, the region, the reconstruction) and
// the rays' part, which grows with them; and the rate changes with the scene,
// the lens (a wide aperture spreads rays over more of the scene) and the
// device. FrameBudget learns both parts from the frames it is told about
// (device time, FrameTimings::device_s, so that host latency does not count)
// and chooses the next frame's rays per pixel to fill the target:
//   - each part is an exponential average of the measured ones, so one noisy
//     frame moves the budget a little, a lasting change fully;
//   - a dearer frame shrinks the budget at once (a frame over target is a
//     dropped frame), a cheaper one lets it grow by at most `max_growth`
//     (or one rpp) over the rpp measured (a fast outlier must not make the
//     next frame late).
// Where a renderer does not tell the rays' time apart, the whole frame
// counts as its rays'. Taken so on the CPU reference, README command 1 gave
// 2 rays a pixel to 72 of its 141 frames focused beyond a metre; told
// apart, to 114 of 141 (bench/RESULTS.md).
// A frame told apart after one not (or the other way) starts the averages
// again: a whole frame's time a ray is not the rays' alone.
// The budget is a mean, not a whole number of rays: between 1 and 2 rays a
// pixel lies a frame's worth of time, and a frame that shares its rays
// unevenly spends a fraction of one where its picture lacks them most (a
// first frame's sharp edges; ray_shares.h). With fractions, README command
// 1 gave more than one ray a pixel to 134 of its 137 frames focused beyond
// a metre (1.5 or more to 122), none dropped (bench/RESULTS.md).
// Pure arithmetic on the timings it is given: testable with a made-up clock.
#pragma once

#include <cmath>
#include <cstdint>

namespace camhead::renderer {

// A mean of rays per pixel is given in sixteenths of a ray, the budget's and
// a frame request's alike (set_mean_rays_per_pixel, frame_renderer.h): the
// fraction is then exact in a float, and below 1.
inline constexpr double kRaySteps = 16.0;

// `rays` rounded down to sixteenths of a ray (kRaySteps).
[[nodiscard]] inline double in_ray_steps(double rays) {
  return std::floor(rays * kRaySteps) / kRaySteps;
}

struct FrameBudgetSettings {
  double target_s = 1.0 / 30.0;
  std::uint32_t min_rpp = 1;
  std::uint32_t max_rpp = 1024;
  // Weight of the newest frame in the average cost per rpp.
  double smoothing = 0.3;
  // Largest factor by which the budget grows from one frame to the next.
  double max_growth = 1.5;
  // Fraction of the target to aim at, headroom for frame-to-frame noise:
  // with whole rays a pixel, and with a fraction of one more. Frames filled
  // to 0.9 of the target with fractions ran past it in one of six (the
  // locked-off rig on 2 cores, bench/RESULTS.md); whole rays leave room
  // below it as a rule.
  double headroom = 0.9;
  double fraction_headroom = 0.85;
};

class FrameBudget {
public:
  // Throws std::invalid_argument for a target <= 0, min_rpp > max_rpp (or
  // 0), or headrooms outside (0, 1] (the fraction's above the whole rays').
  explicit FrameBudget(const FrameBudgetSettings &settings);

  // Rays per pixel for the next frame, a mean in sixteenths of a ray (exact
  // in a float): its whole part is rpp(), and the rest a frame that shares
  // its rays unevenly spends (FrameRequest::extra_rays_per_pixel).
  [[nodiscard]] double rays_per_pixel() const { return rays_; }
  // Its whole part, for a frame that traces every pixel alike.
  [[nodiscard]] std::uint32_t rpp() const { return std::uint32_t(rays_); }
  // A frame of `rpp` rays per pixel (a mean: an accumulating frame shares
  // its rays unevenly) took `seconds`, `rays_seconds` of them tracing its
  // rays (0: not told apart, all of it); ignored unless rpp and seconds > 0.
  void measured(double rpp, double seconds, double rays_seconds = 0.0);

private:
  FrameBudgetSettings settings_;
  double rays_;
  double seconds_per_rpp_ = 0.0;
  double fixed_seconds_ = 0.0;
  bool measured_ = false;
  bool apart_ = false; // whether the averages are of frames told apart
};

} // namespace camhead::renderer
