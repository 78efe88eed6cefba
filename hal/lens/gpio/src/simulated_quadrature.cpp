// Trajectory -> quadrature edges, and the simulated edge source. See
// simulated_quadrature.h for the model.
#include "camhead/hal/lens/gpio/simulated_quadrature.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace camhead::hal::lens::gpio {
namespace {

constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();

// The count changes from `from` to `to` (adjacent) at t_ns.
struct Crossing {
  std::int64_t t_ns;
  std::int64_t from, to;
};

std::vector<Crossing> crossings(const std::vector<TrajectoryPoint> &points) {
  std::vector<Crossing> out;
  for (std::size_t i = 1; i < points.size(); ++i) {
    const double p0 = points[i - 1].counts, p1 = points[i].counts;
    const std::int64_t t0 = points[i - 1].t_ns, t1 = points[i].t_ns;
    // The count is floor(position): going up it becomes c when the position
    // reaches c; going down it becomes c - 1 when the position leaves c.
    const auto time_at = [&](double c) {
      return t0 + std::llround((c - p0) / (p1 - p0) * static_cast<double>(t1 - t0));
    };
    const auto c0 = static_cast<std::int64_t>(std::floor(p0));
    const auto c1 = static_cast<std::int64_t>(std::floor(p1));
    if (p1 > p0) {
      for (std::int64_t c = c0 + 1; c <= c1; ++c) {
        out.push_back({time_at(static_cast<double>(c)), c - 1, c});
      }
    } else if (p1 < p0) {
      for (std::int64_t c = c0; c > c1; --c) {
        out.push_back({time_at(static_cast<double>(c)), c, c - 1});
      }
    }
  }
  return out;
}

bool contains(const std::vector<std::uint64_t> &ordinals, std::uint64_t k) {
  return std::find(ordinals.begin(), ordinals.end(), k) != ordinals.end();
}

void sort_by_time(std::vector<EdgeEvent> &events) {
  std::stable_sort(events.begin(), events.end(),
                   [](const EdgeEvent &x, const EdgeEvent &y) { return x.t_ns < y.t_ns; });
}

std::int64_t start_count(const SimulatedQuadratureAxis &motion) {
  return motion.trajectory.empty()
             ? 0
             : static_cast<std::int64_t>(std::floor(motion.trajectory.front().counts));
}

} // namespace

AxisLevels quadrature_levels(std::int64_t count, std::optional<std::int32_t> index_count) {
  const std::int64_t quarter = ((count % 4) + 4) % 4; // Gray 00, 10, 11, 01
  return AxisLevels{quarter == 1 || quarter == 2, quarter == 2 || quarter == 3,
                    index_count.has_value() && count == *index_count};
}

std::vector<EdgeEvent> quadrature_edges(LensAxis axis, const SimulatedQuadratureAxis &motion) {
  // The clean edge sequence, remembering where each A/B edge (by ordinal) is.
  std::vector<EdgeEvent> clean;
  std::vector<std::size_t> ab_at;
  for (const Crossing &c : crossings(motion.trajectory)) {
    const AxisLevels from = quadrature_levels(c.from, motion.index_count);
    const AxisLevels to = quadrature_levels(c.to, motion.index_count);
    // A gated index falls as its quarter is left and rises once it is
    // entered: same timestamp, listed in that physical order.
    if (from.index && !to.index) {
      clean.push_back({c.t_ns, axis, QuadratureLine::index, false});
    }
    ab_at.push_back(clean.size());
    if (from.a != to.a) {
      clean.push_back({c.t_ns, axis, QuadratureLine::a, to.a});
    } else {
      clean.push_back({c.t_ns, axis, QuadratureLine::b, to.b});
    }
    if (!from.index && to.index) {
      clean.push_back({c.t_ns, axis, QuadratureLine::index, true});
    }
  }

  const EdgeFaults &f = motion.faults;
  std::vector<EdgeEvent> out;
  out.reserve(clean.size() + 2 * (f.bounced.size() + f.duplicated.size()));
  std::size_t next_ab = 0;
  for (std::size_t i = 0; i < clean.size(); ++i) {
    const bool is_ab = next_ab < ab_at.size() && ab_at[next_ab] == i;
    if (!is_ab) {
      out.push_back(clean[i]);
      continue;
    }
    const std::uint64_t k = next_ab++;
    const std::int64_t next_t = next_ab < ab_at.size() ? clean[ab_at[next_ab]].t_ns : kNever;
    EdgeEvent e = clean[i];
    if (contains(f.dropped, k)) {
      continue;
    }
    if (contains(f.merged, k) && next_t != kNever) {
      e.t_ns = next_t;
    }
    out.push_back(e);
    const bool fits = f.bounce_ns > 0 && (next_t == kNever || 3 * f.bounce_ns <= next_t - e.t_ns);
    if (fits && contains(f.bounced, k)) {
      out.push_back({e.t_ns + f.bounce_ns, axis, e.line, !e.level});
      out.push_back({e.t_ns + 2 * f.bounce_ns, axis, e.line, e.level});
    }
    if (fits && contains(f.duplicated, k)) {
      out.push_back({e.t_ns + f.bounce_ns, axis, e.line, e.level});
    }
  }
  sort_by_time(out);
  return out;
}

SimulatedQuadrature::SimulatedQuadrature(const SimulatedQuadratureConfig &config)
    : clock_(config.clock), wake_latency_(config.wake_latency) {
  const std::pair<LensAxis, const std::optional<SimulatedQuadratureAxis> *> axes[] = {
      {LensAxis::focus, &config.focus},
      {LensAxis::iris, &config.iris},
      {LensAxis::zoom, &config.zoom}};
  for (const auto &[axis, motion] : axes) {
    if (!motion->has_value()) {
      continue;
    }
    const auto i = static_cast<std::size_t>(axis);
    axes_[i] = true;
    const std::vector<EdgeEvent> reported = quadrature_edges(axis, **motion);
    reported_.insert(reported_.end(), reported.begin(), reported.end());
    SimulatedQuadratureAxis clean = **motion;
    clean.faults = {};
    const std::vector<EdgeEvent> physical = quadrature_edges(axis, clean);
    physical_.insert(physical_.end(), physical.begin(), physical.end());
    truth_levels_[i] = quadrature_levels(start_count(**motion), (*motion)->index_count);
  }
  if (std::none_of(axes_.begin(), axes_.end(), [](bool b) { return b; })) {
    throw std::invalid_argument(
        "gpio sim: no axis configured; set at least one of focus, iris, zoom");
  }
  sort_by_time(reported_);
  sort_by_time(physical_);
}

std::int64_t SimulatedQuadrature::now_ns() const {
  return clock_ == SimClock::virtual_time ? now_ns_ : monotonic_ns();
}

void SimulatedQuadrature::sleep_for(std::chrono::nanoseconds duration) {
  if (clock_ == SimClock::virtual_time) {
    now_ns_ += std::max<std::int64_t>(duration.count(), 0);
  } else {
    EdgeSource::sleep_for(duration);
  }
}

bool SimulatedQuadrature::open(std::string &error) {
  if (!present_) {
    error = name() + ": cannot open chip: No such file or directory (simulated unplug)";
    return false;
  }
  if (!started_) {
    t0_ns_ = clock_ == SimClock::virtual_time ? 0 : monotonic_ns();
    now_ns_ = t0_ns_;
    started_ = true;
  }
  // A fresh request sees no edges from before it: skip the gap.
  const std::int64_t now = now_ns();
  while (next_reported_ < reported_.size() && t0_ns_ + reported_[next_reported_].t_ns <= now) {
    ++next_reported_;
  }
  advance_truth(now);
  open_ = true;
  return true;
}

void SimulatedQuadrature::advance_truth(std::int64_t t_ns) {
  while (next_physical_ < physical_.size() && t0_ns_ + physical_[next_physical_].t_ns <= t_ns) {
    const EdgeEvent &e = physical_[next_physical_++];
    AxisLevels &l = truth_levels_[static_cast<std::size_t>(e.axis)];
    switch (e.line) {
    case QuadratureLine::a:
      l.a = e.level;
      break;
    case QuadratureLine::b:
      l.b = e.level;
      break;
    case QuadratureLine::index:
      l.index = e.level;
      break;
    }
  }
}

bool SimulatedQuadrature::read_levels(AllLevels &levels, std::int64_t &t_ns, std::string &error) {
  if (!open_ || !present_) {
    error = name() + ": cannot read levels: No such device (simulated unplug)";
    return false;
  }
  t_ns = now_ns();
  advance_truth(t_ns);
  levels = truth_levels_;
  return true;
}

bool SimulatedQuadrature::wait_edges(std::chrono::milliseconds timeout, std::vector<EdgeEvent> &out,
                                     std::string &error) {
  if (!open_ || !present_) {
    error = name() + ": cannot read events: No such device (simulated unplug)";
    return false;
  }
  const std::int64_t now = now_ns();
  const std::int64_t deadline =
      now + std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
  const std::int64_t next =
      next_reported_ < reported_.size() ? t0_ns_ + reported_[next_reported_].t_ns : kNever;
  if (next > now) {
    // Sleep until the first edge (plus the reader's wake-up) or the timeout.
    const std::int64_t wake =
        next <= deadline ? std::min(next + wake_latency_.count(), deadline) : deadline;
    sleep_for(std::chrono::nanoseconds(wake - now));
  }
  const std::int64_t until = now_ns();
  while (next_reported_ < reported_.size() && t0_ns_ + reported_[next_reported_].t_ns <= until) {
    EdgeEvent e = reported_[next_reported_++];
    e.t_ns += t0_ns_;
    out.push_back(e);
  }
  return true;
}

std::unique_ptr<QuadratureEncoder>
open_simulated_quadrature(const SimulatedQuadratureConfig &config) {
  AxisConfigs decoders{};
  const std::pair<LensAxis, const std::optional<SimulatedQuadratureAxis> *> axes[] = {
      {LensAxis::focus, &config.focus},
      {LensAxis::iris, &config.iris},
      {LensAxis::zoom, &config.zoom}};
  for (const auto &[axis, motion] : axes) {
    if (motion->has_value()) {
      decoders[static_cast<std::size_t>(axis)] = (*motion)->decoder;
    }
  }
  QuadratureEncoderOptions options;
  options.reopen_interval = config.reopen_interval;
  return std::make_unique<QuadratureEncoder>(std::make_unique<SimulatedQuadrature>(config),
                                             decoders, options);
}

} // namespace camhead::hal::lens::gpio
