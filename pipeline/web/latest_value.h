// The newest value from one writer for one reader, without a lock: a triple
// buffer. The writer fills back() and publish()es it; the reader take()s the
// newest published value into front() and reads it there. Neither ever
// waits for the other, so the frame loop can hand the operator page a value
// a frame and the page can read at its own pace; a value not taken before
// the next publish() is replaced (the reader only ever wants the newest).
// The three values are made once, with the buffer: publishing copies and
// allocates nothing (the frame loop's rule), the values' own storage is
// reused as it is.
//
// Thread safety: one writer thread (back, publish), one reader thread
// (take, front).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace camhead::pipeline::web {

template <typename T> class LatestValue {
public:
  // Each of the three values starts as a copy of `initial` (sized storage
  // included: a preview image's pixels are allocated here).
  explicit LatestValue(const T &initial = T()) : values_{initial, initial, initial} {}

  // The writer's value, to fill before publish().
  [[nodiscard]] T &back() { return values_[back_]; }
  // Makes back() the newest value; back() is then another of the three.
  void publish() {
    const std::uint8_t old =
        middle_.exchange(std::uint8_t(back_ | kFresh), std::memory_order_acq_rel);
    back_ = old & kIndex;
  }

  // Whether a value newer than front() was published; if so it is front() now.
  bool take() {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0)
      return false;
    const std::uint8_t old = middle_.exchange(front_, std::memory_order_acq_rel);
    front_ = old & kIndex;
    return true;
  }
  // The reader's value: the newest taken (as made, before the first).
  [[nodiscard]] const T &front() const { return values_[front_]; }

private:
  static constexpr std::uint8_t kIndex = 0x3, kFresh = 0x4;
  std::array<T, 3> values_;
  std::uint8_t back_ = 0;               // the writer's
  std::atomic<std::uint8_t> middle_{1}; // the one between, and whether it is new
  std::uint8_t front_ = 2;              // the reader's
};

} // namespace camhead::pipeline::web
