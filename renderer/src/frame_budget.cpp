#include "camhead/renderer/frame_budget.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace camhead::renderer {

FrameBudget::FrameBudget(const FrameBudgetSettings &settings)
    : settings_(settings), rays_(settings.min_rpp) {
  if (!(settings.target_s > 0.0))
    throw std::invalid_argument("frame-time target must be > 0 s, not " +
                                std::to_string(settings.target_s));
  if (!(settings.headroom > 0.0 && settings.headroom <= 1.0 && settings.fraction_headroom > 0.0 &&
        settings.fraction_headroom <= settings.headroom))
    throw std::invalid_argument("headroom " + std::to_string(settings.headroom) +
                                " and fraction headroom " +
                                std::to_string(settings.fraction_headroom) +
                                " must be in (0, 1], the fraction's no larger");
  if (settings.min_rpp == 0 || settings.min_rpp > settings.max_rpp)
    throw std::invalid_argument("rays per pixel range " + std::to_string(settings.min_rpp) + ".." +
                                std::to_string(settings.max_rpp) + " is empty or 0");
}

void FrameBudget::measured(double rpp, double seconds, double rays_seconds) {
  if (!(rpp > 0.0) || !std::isfinite(rpp) || !(seconds > 0.0) || !std::isfinite(seconds))
    return;
  const bool apart = rays_seconds > 0.0 && rays_seconds <= seconds;
  const double per_rpp = (apart ? rays_seconds : seconds) / rpp;
  const double fixed = apart ? seconds - rays_seconds : 0.0;
  if (apart != apart_)
    measured_ = false;
  apart_ = apart;
  const double a = settings_.smoothing;
  seconds_per_rpp_ = measured_ ? a * per_rpp + (1.0 - a) * seconds_per_rpp_ : per_rpp;
  fixed_seconds_ = measured_ ? a * fixed + (1.0 - a) * fixed_seconds_ : fixed;
  measured_ = true;
  // A frame that came out dear counts at once, not averaged away.
  const double cost = std::max(seconds_per_rpp_, per_rpp);
  const double fixed_part = std::max(fixed_seconds_, fixed);
  const auto fits = [&](double headroom) {
    return (headroom * settings_.target_s - fixed_part) / cost;
  };
  const double most = std::max(rpp + 1.0, rpp * settings_.max_growth);
  // Whole rays within the headroom, or a ray's sixteenths within the
  // fraction's, whichever gives more.
  const double whole = std::floor(std::min(fits(settings_.headroom), most));
  const double sixteenths = in_ray_steps(std::min(fits(settings_.fraction_headroom), most));
  rays_ =
      std::clamp(std::max(whole, sixteenths), double(settings_.min_rpp), double(settings_.max_rpp));
}

} // namespace camhead::renderer
