// A ring of values from one writer to one reader, without a lock: the frame
// loop's per-frame records to the operator page, which reads them in bursts
// (its history of the last minute: latency per stage, the lens over time).
// A full ring refuses the new value and counts it, so the writer never
// waits; its slots are made with it (nothing is allocated per value).
//
// Thread safety: one writer thread (push), one reader thread (pop, dropped).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <type_traits>
#include <vector>

namespace camhead::pipeline::web {

template <typename T> class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "values are copied in and out of the slots");

public:
  explicit SpscRing(std::size_t capacity) : slots_(capacity + 1) {}

  // Adds `value`, or counts it dropped when the reader is `capacity` behind.
  void push(const T &value) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    const std::size_t next = head + 1 == slots_.size() ? 0 : head + 1;
    if (next == tail_.load(std::memory_order_acquire)) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    slots_[head] = value;
    head_.store(next, std::memory_order_release);
  }

  // The oldest value not yet read, if any.
  std::optional<T> pop() {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire))
      return std::nullopt;
    T value = slots_[tail];
    tail_.store(tail + 1 == slots_.size() ? 0 : tail + 1, std::memory_order_release);
    return value;
  }

  // Values refused because the ring was full, so far.
  [[nodiscard]] std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

private:
  std::vector<T> slots_;
  std::atomic<std::size_t> head_{0}; // the next slot to write: the writer's
  std::atomic<std::size_t> tail_{0}; // the next slot to read: the reader's
  std::atomic<std::uint64_t> dropped_{0};
};

} // namespace camhead::pipeline::web
