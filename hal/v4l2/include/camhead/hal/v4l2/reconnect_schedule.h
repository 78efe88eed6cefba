// When to try a device again after it went away: every `interval` from the
// loss, measured on CLOCK_MONOTONIC. A camera unplugged for a minute is tried
// 240 times, each a failed open() of a missing node (microseconds), so a
// steady interval costs nothing and takes the device back within a quarter
// of a second of its return (the picture within half a second, as a camera
// head must: the hardware lab's vivid check measures it); udev's by-id link
// may point at another /dev/videoN by then, which is why the backends reopen
// by the name they were given.
//
// Thread safety: none; the thread that waits for frames owns it.
#pragma once

#include <cstdint>

namespace camhead::hal::v4l2 {

class ReconnectSchedule {
public:
  static constexpr std::int64_t kDefaultIntervalNs = 250'000'000;

  explicit ReconnectSchedule(std::int64_t interval_ns = kDefaultIntervalNs)
      : interval_ns_(interval_ns) {}

  // The device was lost at `now_ns`: the first try comes one interval later,
  // so that an unplug has finished (udev has removed the node) before it.
  void lost(std::int64_t now_ns);

  // True when a try is due at `now_ns` (never before lost()).
  [[nodiscard]] bool due(std::int64_t now_ns) const;

  // A try at `now_ns` failed: the next is one interval after it. Tries that
  // come late (the caller waited for frames elsewhere) do not bunch up.
  void failed(std::int64_t now_ns);

  // The device is back; due() is false until the next lost().
  void succeeded();

  [[nodiscard]] bool waiting() const { return waiting_; }
  // When the next try is due; meaningful while waiting().
  [[nodiscard]] std::int64_t next_ns() const { return next_ns_; }
  // Tries that failed since the loss.
  [[nodiscard]] std::uint64_t failures() const { return failures_; }

private:
  std::int64_t interval_ns_;
  bool waiting_ = false;
  std::int64_t next_ns_ = 0;
  std::uint64_t failures_ = 0;
};

} // namespace camhead::hal::v4l2
