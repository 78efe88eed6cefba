// libgpiod 1.6 edge source. See gpiod_edge_source.h for handle ownership and
// gpio_quadrature.h for what the v1 uAPI guarantees and what it does not.
#include "gpiod_edge_source.h"

#include <algorithm>
#include <cerrno>
#include <ctime>
#include <optional>
#include <system_error>
#include <utility>

namespace camhead::hal::lens::gpio::detail {
namespace {

constexpr std::int64_t kNanosPerSecond = 1'000'000'000;
// Rounds of "read what is ready, look again without waiting" per wait: enough
// to collect a burst whole so it can be ordered, few enough that an edge
// storm cannot hold poll() past its timeout for long.
constexpr int kMaxDrainRounds = 8;

std::string errno_text(int err) {
  return err != 0 ? std::system_category().message(err) : std::string("unknown error");
}

const char *line_letter(QuadratureLine line) {
  switch (line) {
  case QuadratureLine::a:
    return "A";
  case QuadratureLine::b:
    return "B";
  case QuadratureLine::index:
    return "index";
  }
  return "?";
}

int bias_flags(GpioBias bias) {
  switch (bias) {
  case GpioBias::as_is:
    return 0;
  case GpioBias::disable:
    return GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE;
  case GpioBias::pull_up:
    return GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP;
  case GpioBias::pull_down:
    return GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN;
  }
  return 0;
}

} // namespace

GpiodEdgeSource::GpiodEdgeSource(const GpioQuadratureConfig &config)
    : chip_descr_(config.chip), consumer_(config.consumer),
      request_flags_(bias_flags(config.bias)) {
  const std::pair<LensAxis, const std::optional<GpioQuadratureAxis> *> axes[] = {
      {LensAxis::focus, &config.focus},
      {LensAxis::iris, &config.iris},
      {LensAxis::zoom, &config.zoom}};
  for (const auto &[axis, spec] : axes) {
    if (!spec->has_value()) {
      continue;
    }
    const GpioQuadratureAxis &a = **spec;
    axes_[static_cast<std::size_t>(axis)] = true;
    roles_.push_back({axis, QuadratureLine::a, a.line_a, false});
    roles_.push_back({axis, QuadratureLine::b, a.line_b, false});
    if (a.line_index) {
      roles_.push_back({axis, QuadratureLine::index, *a.line_index, a.index_active_low});
    }
  }
}

std::string GpiodEdgeSource::line_name(const LineRole &role) const {
  std::string chip = "gpio " + chip_descr_;
  if (!chip_name_.empty() && chip_name_ != chip_descr_) {
    chip += " (" + chip_name_ + ")";
  }
  return chip + " line " + std::to_string(role.offset) + " (" + to_string(role.axis) + ' ' +
         line_letter(role.line) + ")";
}

bool GpiodEdgeSource::open(std::string &error) {
  close();
  if (const std::string &why = gpiod_load_error(); !why.empty()) {
    error = name() + ": " + why;
    return false;
  }
  errno = 0;
  ChipHandle chip(gpiod().chip_open_lookup(chip_descr_.c_str()));
  if (!chip) {
    error = name() + ": cannot open chip: " +
            (errno != 0 ? errno_text(errno) : std::string("no chip by that name, path or label"));
    return false;
  }
  chip_name_ = gpiod().chip_name(chip.get());
  const unsigned num_lines = gpiod().chip_num_lines(chip.get());

  // One request per line rather than gpiod_line_request_bulk_*: libgpiod 1.6
  // makes one v1 event request per line either way, but this way a failure
  // names its line and each line can carry its own active-low flag.
  std::vector<gpiod_line *> lines;
  for (const LineRole &role : roles_) {
    if (role.offset >= num_lines) {
      error =
          line_name(role) + ": no such line; the chip has " + std::to_string(num_lines) + " lines";
      return false; // `chip` closes and releases the lines requested so far
    }
    gpiod_line *line = gpiod().chip_get_line(chip.get(), role.offset);
    if (line == nullptr) {
      error = line_name(role) + ": cannot get line: " + errno_text(errno);
      return false;
    }
    const int flags = request_flags_ | (role.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0);
    if (gpiod().line_request_both_edges_events_flags(line, consumer_.c_str(), flags) < 0) {
      const int err = errno;
      error = line_name(role) + ": cannot request both-edge events: " + errno_text(err);
      if (err == EBUSY && gpiod().line_update(line) == 0 &&
          gpiod().line_consumer(line) != nullptr) {
        error += std::string("; used by \"") + gpiod().line_consumer(line) + '"';
      }
      return false;
    }
    lines.push_back(line);
  }
  chip_ = std::move(chip);
  lines_ = std::move(lines);
  return true;
}

void GpiodEdgeSource::close() {
  lines_.clear();
  chip_.reset(); // releases every requested line
}

bool GpiodEdgeSource::read_levels(AllLevels &levels, std::int64_t &t_ns, std::string &error) {
  levels = {};
  if (!chip_) {
    error = name() + ": not open";
    return false;
  }
  for (std::size_t i = 0; i < lines_.size(); ++i) {
    const int value = gpiod().line_get_value(lines_[i]);
    if (value < 0) {
      error = line_name(roles_[i]) + ": cannot read level: " + errno_text(errno);
      return false;
    }
    AxisLevels &l = levels[static_cast<std::size_t>(roles_[i].axis)];
    switch (roles_[i].line) {
    case QuadratureLine::a:
      l.a = value != 0;
      break;
    case QuadratureLine::b:
      l.b = value != 0;
      break;
    case QuadratureLine::index:
      l.index = value != 0;
      break;
    }
  }
  t_ns = monotonic_ns();
  return true;
}

bool GpiodEdgeSource::wait_edges(std::chrono::milliseconds timeout, std::vector<EdgeEvent> &out,
                                 std::string &error) {
  if (!chip_) {
    error = name() + ": not open";
    return false;
  }
  gpiod_line_bulk all;
  gpiod_line_bulk_init(&all);
  for (gpiod_line *line : lines_) {
    gpiod_line_bulk_add(&all, line);
  }
  const std::size_t first = out.size();
  const auto ms = std::max<std::int64_t>(timeout.count(), 0);
  timespec wait{static_cast<time_t>(ms / 1000), static_cast<long>((ms % 1000) * 1'000'000)};
  gpiod_line_bulk ready;
  int rv = gpiod().line_event_wait_bulk(&all, &wait, &ready);
  bool ok = true;
  // One offset for every round's realtime stamps (kernels before 5.7): they
  // are sorted together below, and two offsets could swap an A edge and a B
  // edge read in different rounds.
  std::optional<base::ClockPair> clocks;
  for (int round = 0; rv > 0 && ok && round < kMaxDrainRounds; ++round) {
    ok = read_ready(ready, clocks, out, error);
    if (ok) {
      const timespec zero{};
      rv = gpiod().line_event_wait_bulk(&all, &zero, &ready);
    }
  }
  if (ok && rv < 0) {
    error = name() + ": cannot wait for events: " + errno_text(errno);
    ok = false;
  }
  // Each line has its own kernel queue: only the timestamps order A against
  // B. Stable, so that events of one line keep the kernel's order.
  std::stable_sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(),
                   [](const EdgeEvent &x, const EdgeEvent &y) { return x.t_ns < y.t_ns; });
  return ok;
}

bool GpiodEdgeSource::read_ready(gpiod_line_bulk &ready, std::optional<base::ClockPair> &clocks,
                                 std::vector<EdgeEvent> &out, std::string &error) {
  const std::int64_t now_ns = monotonic_ns();
  for (unsigned i = 0; i < gpiod_line_bulk_num_lines(&ready); ++i) {
    gpiod_line *line = gpiod_line_bulk_get_line(&ready, i);
    const auto it = std::find(lines_.begin(), lines_.end(), line);
    if (it == lines_.end()) {
      continue;
    }
    const LineRole &role = roles_[static_cast<std::size_t>(it - lines_.begin())];
    // Ready means at least one event (or a hang-up, which fails the read),
    // so this read does not block.
    const int n = gpiod().line_event_read_multiple(line, buffer_.data(),
                                                   static_cast<unsigned>(buffer_.size()));
    if (n < 0) {
      error = line_name(role) + ": cannot read events: " + errno_text(errno);
      return false;
    }
    for (int k = 0; k < n; ++k) {
      const gpiod_line_event &e = buffer_[static_cast<std::size_t>(k)];
      out.push_back(EdgeEvent{to_monotonic_ns(e.ts, now_ns, clocks), role.axis, role.line,
                              e.event_type == GPIOD_LINE_EVENT_RISING_EDGE});
    }
  }
  return true;
}

std::int64_t GpiodEdgeSource::to_monotonic_ns(const timespec &ts, std::int64_t now_ns,
                                              std::optional<base::ClockPair> &clocks) {
  const std::int64_t stamp = static_cast<std::int64_t>(ts.tv_sec) * kNanosPerSecond + ts.tv_nsec;
  if (stamp <= now_ns + kNanosPerSecond) {
    return stamp;
  }
  // Ahead of the monotonic clock: a kernel before 5.7 stamped CLOCK_REALTIME.
  if (!clocks) {
    clocks = base::read_clock_pair();
  }
  // Without an offset (a realtime step inside every bracket), the latest the
  // edge can have been: now, after its line was read.
  return clocks->known() ? clocks->monotonic_of(stamp) : monotonic_ns();
}

} // namespace camhead::hal::lens::gpio::detail
