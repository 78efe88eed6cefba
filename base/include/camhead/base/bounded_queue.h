// A bounded queue between two pipeline threads in which the newest item wins:
// a full queue drops its oldest item to take a new one, and says so, so that
// a stage slower than its producer works on the latest frame, never on a
// backlog, and every drop is counted by whoever pushed. Its slots are made
// with it: pushing and popping allocate nothing (the frame loop's rule).
//
// Thread safety: any number of producers and consumers.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

namespace camhead::base {

template <typename T> class BoundedQueue {
  // Items move in and out of the slots under the lock: a move that threw
  // (or allocated) would break the queue's promise.
  static_assert(std::is_nothrow_move_constructible_v<T>);

public:
  explicit BoundedQueue(std::size_t capacity) : slots_(capacity > 0 ? capacity : 1) {}

  // Adds `item`; when the queue is full the oldest item is taken out and
  // returned (the caller counts it as dropped and releases what it holds).
  // After close() the item itself comes back.
  std::optional<T> push(T item) {
    std::optional<T> dropped;
    {
      std::lock_guard lock(mutex_);
      if (closed_)
        return std::optional<T>(std::move(item));
      if (size_ == slots_.size())
        dropped.emplace(take_oldest());
      put(std::move(item));
    }
    ready_.notify_one();
    return dropped;
  }

  // Adds `item` once there is room, waiting for it: for a producer that
  // must lose nothing (a file played as fast as it is taken). After close()
  // the item itself comes back.
  std::optional<T> push_waiting(T item) {
    {
      std::unique_lock lock(mutex_);
      room_.wait(lock, [&] { return closed_ || size_ < slots_.size(); });
      if (closed_)
        return std::optional<T>(std::move(item));
      put(std::move(item));
    }
    ready_.notify_one();
    return std::nullopt;
  }

  // The oldest item, waiting at most `timeout`; empty on time-out, or once
  // the queue is closed and drained.
  std::optional<T> pop(std::chrono::nanoseconds timeout) {
    std::unique_lock lock(mutex_);
    if (!ready_.wait_for(lock, timeout, [&] { return size_ > 0 || closed_; }))
      return std::nullopt;
    if (size_ == 0)
      return std::nullopt;
    std::optional<T> item(take_oldest());
    room_.notify_one();
    return item;
  }

  // Wakes every waiting pop(); later pushes are refused. Items still queued
  // can be popped.
  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
    room_.notify_all();
  }

  [[nodiscard]] bool closed() const {
    std::lock_guard lock(mutex_);
    return closed_;
  }

  // Closed with nothing left to pop: what a consumer whose pop() came back
  // empty checks before it stops, since an item may have come between the
  // two (pushed just before the close).
  [[nodiscard]] bool drained() const {
    std::lock_guard lock(mutex_);
    return closed_ && size_ == 0;
  }

private:
  // A ring of slots, oldest at head_; with the lock held.
  void put(T item) {
    slots_[(head_ + size_) % slots_.size()].emplace(std::move(item));
    ++size_;
  }
  T take_oldest() {
    std::optional<T> &slot = slots_[head_];
    T item(std::move(*slot));
    slot.reset();
    head_ = (head_ + 1) % slots_.size();
    --size_;
    return item;
  }

  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::condition_variable room_;
  std::vector<std::optional<T>> slots_;
  std::size_t head_ = 0, size_ = 0;
  bool closed_ = false;
};

} // namespace camhead::base
