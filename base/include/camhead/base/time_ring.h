// The recent history of a timed quantity, oldest first, in storage made
// once: the lens axes' timelines (lens_control/time_alignment.h) and the
// tracked poses' (pipeline/tracking/pose_timeline.h) both keep one, and
// read it at a frame's instant by the same search.
//
// `Entry` is any copyable type with a `std::int64_t t_ns` member. push()
// and the reads allocate nothing. Thread safety: none.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace camhead::base {

template <class Entry> class TimeRing {
public:
  // Holds the last `capacity` entries (at least two).
  explicit TimeRing(std::size_t capacity) : ring_(std::max<std::size_t>(capacity, 2)) {}

  // Adds `e` after the newest, the oldest making way when full. An entry
  // not later than the newest is ignored: returns false.
  bool push(const Entry &e) {
    if (size_ > 0 && e.t_ns <= (*this)[size_ - 1].t_ns)
      return false;
    if (size_ == ring_.size()) {
      ring_[head_] = e;
      head_ = (head_ + 1) % ring_.size();
    } else {
      ring_[(head_ + size_) % ring_.size()] = e;
      ++size_;
    }
    return true;
  }

  [[nodiscard]] std::size_t size() const { return size_; }
  // The i-th oldest entry.
  [[nodiscard]] const Entry &operator[](std::size_t i) const {
    return ring_[(head_ + i) % ring_.size()];
  }

  // For an instant within [oldest, newest): the i with entry i at or before
  // it and entry i + 1 after it.
  [[nodiscard]] std::size_t bracket(std::int64_t t_ns) const {
    std::size_t lo = 0, hi = size_ - 1; // (*this)[lo] <= t < (*this)[hi]
    while (hi - lo > 1) {
      const std::size_t mid = (lo + hi) / 2;
      if ((*this)[mid].t_ns <= t_ns)
        lo = mid;
      else
        hi = mid;
    }
    return lo;
  }

private:
  std::vector<Entry> ring_;
  std::size_t head_ = 0, size_ = 0;
};

} // namespace camhead::base
