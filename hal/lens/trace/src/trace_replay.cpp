// Real-time playback of a lens trace. See trace_replay.h for the timing model.
#include "camhead/hal/lens/trace/trace_replay.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <ctime>
#include <limits>

#include "camhead/hal/lens/monotonic_clock.h"

namespace camhead::hal::lens {
namespace {

class MonotonicClock final : public ReplayClock {
public:
  std::int64_t now_ns() override { return monotonic_ns(); }

  void sleep_until(std::int64_t t_ns) override {
    const timespec until{static_cast<time_t>(t_ns / 1'000'000'000),
                         static_cast<long>(t_ns % 1'000'000'000)};
    // An absolute deadline: a signal that interrupts the sleep does not
    // stretch it when it is resumed.
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR) {
    }
  }
};

} // namespace

ReplayClock &monotonic_replay_clock() {
  static MonotonicClock clock;
  return clock;
}

std::int64_t loop_period_ns(const LensTrace &trace) {
  if (trace.readings.size() < 2)
    return 0;
  const std::int64_t span = trace.readings.back().t_ns - trace.readings.front().t_ns;
  const auto intervals = static_cast<std::int64_t>(trace.readings.size() - 1);
  return span > 0 ? span + span / intervals : 0;
}

TraceReplay::TraceReplay(LensTrace trace, TraceReplayOptions options)
    : trace_(std::move(trace)), loop_enabled_(options.loop), speed_(options.speed),
      clock_(options.clock != nullptr ? options.clock : &monotonic_replay_clock()),
      start_option_(options.start_ns) {
  if (trace_.readings.empty()) {
    throw TraceError(trace_.source, 0, "", "no readings to replay");
  }
  if (!std::isfinite(speed_) || !(speed_ > 0.0)) {
    throw TraceError(trace_.source, 0, "", "replay speed must be > 0 and finite");
  }
  if (loop_enabled_) {
    period_ns_ = loop_period_ns(trace_);
    if (period_ns_ == 0) {
      throw TraceError(trace_.source, 0, "", "cannot loop a trace that spans no time");
    }
  }
}

std::unique_ptr<TraceReplay> TraceReplay::open(const std::filesystem::path &path,
                                               TraceReplayOptions options) {
  return std::make_unique<TraceReplay>(read_lens_trace(path), options);
}

std::string TraceReplay::name() const {
  return "trace " + trace_.source;
}

std::int64_t TraceReplay::due_ns(std::size_t index, std::uint64_t loop) const {
  const std::int64_t t = trace_.readings[index].t_ns, t0 = trace_.readings.front().t_ns;
  // Exact in integers at speed 1 while nothing overflows.
  std::int64_t span = 0, looped = 0, offset = 0, due = 0;
  if (speed_ == 1.0 && !__builtin_sub_overflow(t, t0, &span) &&
      !__builtin_mul_overflow(static_cast<std::int64_t>(loop), period_ns_, &looped) &&
      !__builtin_add_overflow(span, looped, &offset) &&
      !__builtin_add_overflow(start_ns_, offset, &due))
    return due;
  // Otherwise in doubles, exact to the nanosecond up to 2^53 ns (104 days);
  // a time past what int64 holds (a long trace played slowly) is never due,
  // rather than wrapped into the past with every reading due at once.
  const double at = static_cast<double>(start_ns_) +
                    (static_cast<double>(t) - static_cast<double>(t0) +
                     static_cast<double>(loop) * static_cast<double>(period_ns_)) /
                        speed_;
  constexpr double kLatest = 9.2e18; // below INT64_MAX, with a margin for llround
  return at < kLatest ? std::llround(at) : std::numeric_limits<std::int64_t>::max();
}

void TraceReplay::join(std::int64_t from_ns) {
  if (due_ns(0, 0) >= from_ns)
    return;
  if (loop_enabled_ && period_ns_ > 0) {
    const double period = double(period_ns_) / speed_;
    loop_ = std::uint64_t(std::max(0.0, std::floor(double(from_ns - start_ns_) / period)));
  }
  index_ = 0;
  // A trace that is over by then delivers nothing.
  while (!finished_ && due_ns(index_, loop_) < from_ns) {
    if (++index_ == trace_.readings.size()) {
      index_ = 0;
      ++loop_;
      finished_ = !loop_enabled_;
    }
  }
}

std::size_t TraceReplay::emit_due(std::int64_t now, std::vector<EncoderReading> &out) {
  std::size_t emitted = 0;
  while (!finished_ && emitted < kMaxBurst) {
    const std::int64_t due = due_ns(index_, loop_);
    if (due > now) {
      break;
    }
    EncoderReading r = trace_.readings[index_];
    r.t_ns = due;
    out.push_back(r);
    ++emitted;
    ++delivered_;
    if (++index_ == trace_.readings.size()) {
      index_ = 0;
      ++loop_;
      finished_ = !loop_enabled_;
    }
  }
  return emitted;
}

void TraceReplay::poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) {
  const std::int64_t now = clock_->now_ns();
  if (!started_) {
    started_ = true;
    start_ns_ = start_option_.value_or(now);
    join(now - kJoinHistoryNs);
  }
  if (emit_due(now, out) > 0) {
    return;
  }
  const std::int64_t deadline =
      now + std::chrono::nanoseconds(std::max(timeout, std::chrono::milliseconds::zero())).count();
  if (finished_) {
    clock_->sleep_until(deadline);
    return;
  }
  const std::int64_t next = due_ns(index_, loop_);
  if (next > deadline) {
    clock_->sleep_until(deadline);
    return;
  }
  clock_->sleep_until(next);
  emit_due(std::max(clock_->now_ns(), next), out);
}

EncoderStatus TraceReplay::status() const {
  EncoderStatus s;
  s.connected = !finished_;
  s.readings = delivered_;
  if (finished_) {
    s.detail = name() + ": finished after " + std::to_string(delivered_) + " readings";
  } else if (!started_) {
    s.detail = name() + ": ready, starts at the first poll";
  } else {
    s.detail = name() + ": playing" + (loop_enabled_ ? ", loop " + std::to_string(loop_ + 1) : "");
  }
  return s;
}

} // namespace camhead::hal::lens
