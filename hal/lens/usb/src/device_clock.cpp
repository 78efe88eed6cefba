// Device clock -> CLOCK_MONOTONIC; see device_clock.h for the method.
#include "camhead/hal/lens/usb/device_clock.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace camhead::hal::lens {
namespace {

// Rounds towards minus infinity, so that blocks before device time 0 (an
// unwrap below the first report) are as long as the others.
std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}

// A block whose minimum lies this much above the first fit (beyond twice the
// mean residual) was busy all through, not a floor: the second fit drops it.
constexpr double kOutlierMarginNs = 20'000.0;

} // namespace

DeviceClockMapper::DeviceClockMapper(ClockMapperParams p) : p_(p) {
  p_.block_us = std::max<std::int64_t>(p_.block_us, 1);
  p_.max_blocks = std::max<std::size_t>(p_.max_blocks, 2);
  done_.reserve(p_.max_blocks);
}

void DeviceClockMapper::reset() {
  primed_ = false;
  outliers_in_a_row_ = 0;
  done_.clear();
  fitted_ = false;
  intercept_ = slope_ = 0.0;
}

std::int64_t DeviceClockMapper::estimate_at(std::int64_t device_us) const {
  if (!fitted_) {
    std::int64_t lowest = current_.d_ns;
    for (const Floor &f : done_) {
      lowest = std::min(lowest, f.d_ns);
    }
    return lowest;
  }
  // The line through the completed blocks, lowered at once when the block
  // being filled has already found a lower floor (it joins the fit only when
  // it completes).
  const auto line = [this](std::int64_t t) {
    return intercept_ + slope_ * static_cast<double>(t - ref_us_);
  };
  const double below =
      std::min(0.0, static_cast<double>(current_.d_ns - base_ns_) - line(current_.device_us));
  return base_ns_ + std::llround(line(device_us) + below);
}

void DeviceClockMapper::start(std::uint32_t raw, std::int64_t receive_ns) {
  primed_ = true;
  last_raw_ = raw;
  device_us_ = raw;
  outliers_in_a_row_ = 0;
  done_.clear();
  fitted_ = false;
  intercept_ = slope_ = 0.0;
  origin_us_ = device_us_;
  block_index_ = 0;
  current_ = Floor{device_us_, receive_ns - device_us_ * 1000, device_us_, device_us_};
}

void DeviceClockMapper::add_to_estimate(std::int64_t device_us, std::int64_t d_ns) {
  const std::int64_t block = floor_div(device_us - origin_us_, p_.block_us);
  if (block == block_index_) {
    if (d_ns < current_.d_ns) {
      current_.device_us = device_us;
      current_.d_ns = d_ns;
    }
    current_.last_us = device_us;
    return;
  }
  // A block that saw reports over less than half its length (reports
  // stopped, then resumed) has a floor from too few of them to trust.
  if (current_.last_us - current_.first_us >= p_.block_us / 2) {
    if (done_.size() == p_.max_blocks) {
      done_.erase(done_.begin());
    }
    done_.push_back(current_);
    fit();
  }
  current_ = Floor{device_us, d_ns, device_us, device_us};
  block_index_ = block;
}

void DeviceClockMapper::fit() {
  if (done_.size() < 2) {
    fitted_ = false;
    return;
  }
  // Coordinates relative to the newest completed block keep the doubles small
  // (receive times are ~1e15 ns after a few days of uptime).
  ref_us_ = done_.back().device_us;
  base_ns_ = done_.back().d_ns;
  const double max_slope = p_.max_skew_ppm / 1000.0; // ns of offset per us of device time
  std::vector<bool> keep(done_.size(), true);

  const auto solve = [&] {
    double n = 0.0, mx = 0.0, my = 0.0;
    for (std::size_t i = 0; i < done_.size(); ++i) {
      if (keep[i]) {
        n += 1.0;
        mx += static_cast<double>(done_[i].device_us - ref_us_);
        my += static_cast<double>(done_[i].d_ns - base_ns_);
      }
    }
    mx /= n;
    my /= n;
    double sxx = 0.0, sxy = 0.0;
    for (std::size_t i = 0; i < done_.size(); ++i) {
      if (keep[i]) {
        const double x = static_cast<double>(done_[i].device_us - ref_us_) - mx;
        sxx += x * x;
        sxy += x * (static_cast<double>(done_[i].d_ns - base_ns_) - my);
      }
    }
    slope_ = sxx > 0.0 ? std::clamp(sxy / sxx, -max_slope, max_slope) : 0.0;
    intercept_ = my - slope_ * mx;
  };

  solve();
  std::vector<double> residual(done_.size());
  double mean_abs = 0.0;
  for (std::size_t i = 0; i < done_.size(); ++i) {
    residual[i] = static_cast<double>(done_[i].d_ns - base_ns_) -
                  (intercept_ + slope_ * static_cast<double>(done_[i].device_us - ref_us_));
    mean_abs += std::abs(residual[i]);
  }
  mean_abs /= static_cast<double>(done_.size());
  std::size_t kept = 0;
  for (std::size_t i = 0; i < done_.size(); ++i) {
    keep[i] = residual[i] <= 2.0 * mean_abs + kOutlierMarginNs;
    kept += keep[i] ? 1 : 0;
  }
  if (kept >= 2 && kept < done_.size()) {
    solve();
  }
  fitted_ = true;
}

std::int64_t DeviceClockMapper::map(std::uint32_t device_time_us, std::int64_t receive_ns) {
  if (!primed_) {
    start(device_time_us, receive_ns);
    last_out_ns_ = receive_ns;
    return receive_ns;
  }
  // Modular difference read as signed: a wrap 0xFFFFFFF0 -> 0x10 is +0x20.
  const auto step = static_cast<std::int32_t>(device_time_us - last_raw_);
  last_raw_ = device_time_us;
  device_us_ += step;

  const std::int64_t d_ns = receive_ns - device_us_ * 1000;
  std::int64_t estimate = estimate_at(device_us_);
  if (std::llabs(d_ns - estimate) > p_.resync_ns) {
    if (++outliers_in_a_row_ >= p_.resync_after) {
      ++resyncs_;
      start(device_time_us, receive_ns);
      estimate = current_.d_ns;
    }
  } else {
    outliers_in_a_row_ = 0;
    add_to_estimate(device_us_, d_ns);
    estimate = estimate_at(device_us_);
  }

  // Never after the report arrived; strictly later than the previous one
  // while the device time advances, so that a consumer that drops samples not
  // later than its newest (lens_control's AxisTimeline) keeps every one.
  std::int64_t out = std::min(device_us_ * 1000 + estimate, receive_ns);
  if (step > 0 && out <= last_out_ns_) {
    out = last_out_ns_ + 1;
  }
  last_out_ns_ = out;
  return out;
}

} // namespace camhead::hal::lens
