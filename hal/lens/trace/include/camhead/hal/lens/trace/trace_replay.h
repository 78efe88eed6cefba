// A recorded lens trace played back as a live LensEncoder: the simulated
// rig's lens (a looping focus pull, scenes/lenses/sim_focus_pull.csv) and the
// twin of every real encoder backend in tests and demos.
//
// Timing: the replay starts at its first poll(). Reading i of loop k is due at
//   start + ((t_i - t_0) + k * period) / speed
// on the replay clock, and leaves with that instant as t_ns, so downstream
// code sees what a device would have delivered. poll(timeout) returns the
// readings that have come due (oldest first, at most kMaxBurst per call);
// when none has, it waits until the next one is due, or until the timeout if
// that comes first. A finished trace (no loop) delivers nothing more and
// waits out each timeout like a silent device.
//
// Looping: period = the trace's span plus one mean sample interval, so the
// first reading of the next loop follows the last one as the samples follow
// each other. A trace with a single reading or no time span cannot loop.
//
// Thread safety: none. One thread (the lens thread) owns a replay.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camhead/hal/lens/lens_encoder.h"
#include "camhead/hal/lens/trace/lens_trace.h"

namespace camhead::hal::lens {

// The period a looping replay repeats with: the trace's span plus one mean
// sample interval, so that the next loop's first reading follows the last as
// the samples follow each other. 0 for a trace with no time span (fewer
// than two readings, or all at one instant): it cannot loop.
[[nodiscard]] std::int64_t loop_period_ns(const LensTrace &trace);

// The replay's time base. The default is CLOCK_MONOTONIC; tests inject one
// whose sleep_until just moves its own time forward, so they run instantly.
class ReplayClock {
public:
  virtual ~ReplayClock() = default;
  [[nodiscard]] virtual std::int64_t now_ns() = 0;
  // Returns at or after t_ns (immediately when that has passed).
  virtual void sleep_until(std::int64_t t_ns) = 0;
};

// CLOCK_MONOTONIC, sleeping with clock_nanosleep(TIMER_ABSTIME). Stateless;
// shared by every replay that is given no clock.
[[nodiscard]] ReplayClock &monotonic_replay_clock();

struct TraceReplayOptions {
  bool loop = false;
  double speed = 1.0;           // > 0 and finite: 2 plays twice as fast
  ReplayClock *clock = nullptr; // not owned, must outlive the replay; null = monotonic
  // The instant on the replay clock at which the first reading is due; empty:
  // the first poll. A start in the past joins the replay where it would be by
  // now: the first poll delivers the readings due in the last kJoinHistoryNs
  // (history for a lens state a frame ago), not the ones before. With 0 on
  // the monotonic clock, every replay of a trace on the machine plays the
  // same lens at the same instant (the simulated camera films it so).
  std::optional<std::int64_t> start_ns;
};

class TraceReplay final : public LensEncoder {
public:
  // Throws TraceError naming the trace's source for an empty trace, a speed
  // that is not > 0 and finite, or a loop over a trace without a time span.
  explicit TraceReplay(LensTrace trace, TraceReplayOptions options = {});
  // read_lens_trace(path), then the constructor above.
  [[nodiscard]] static std::unique_ptr<TraceReplay> open(const std::filesystem::path &path,
                                                         TraceReplayOptions options = {});

  // "trace FILE"
  [[nodiscard]] std::string name() const override;
  void poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) override;
  // connected while readings remain; lost and malformed stay 0.
  [[nodiscard]] EncoderStatus status() const override;

  [[nodiscard]] bool finished() const { return finished_; }
  [[nodiscard]] std::uint64_t loops_completed() const { return loop_; }
  // Loop period in trace nanoseconds (before the speed factor); 0 without loop.
  [[nodiscard]] std::int64_t period_ns() const { return period_ns_; }

  static constexpr std::size_t kMaxBurst = 4096;
  static constexpr std::int64_t kJoinHistoryNs = 250'000'000;

private:
  [[nodiscard]] std::int64_t due_ns(std::size_t index, std::uint64_t loop) const;
  std::size_t emit_due(std::int64_t now, std::vector<EncoderReading> &out);
  // Skips the readings due before from_ns (a start in the past).
  void join(std::int64_t from_ns);

  LensTrace trace_;
  bool loop_enabled_ = false;
  double speed_ = 1.0;
  ReplayClock *clock_ = nullptr;
  std::int64_t period_ns_ = 0;

  bool started_ = false, finished_ = false;
  std::int64_t start_ns_ = 0;
  std::optional<std::int64_t> start_option_;
  std::size_t index_ = 0; // next reading to deliver
  std::uint64_t loop_ = 0;
  std::uint64_t delivered_ = 0;
};

} // namespace camhead::hal::lens
