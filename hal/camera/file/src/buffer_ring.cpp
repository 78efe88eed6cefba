// See buffer_ring.h.
#include "buffer_ring.h"

#include <chrono>

#include "camhead/base/monotonic_clock.h"

namespace camhead::hal::camera {

BufferRing::BufferRing(int count, std::size_t bytes) : bytes_(bytes), slots_(count) {
  // Uninitialised: every buffer is written whole before it is handed out,
  // and untouched pages of a large frame cost no memory until then.
  for (Slot &slot : slots_)
    slot.data.reset(new std::uint8_t[bytes]);
}

int BufferRing::wait_free(std::int64_t deadline_ns) {
  std::unique_lock lock(mutex_);
  for (;;) {
    for (std::size_t i = 0; i < slots_.size(); ++i)
      if (!slots_[i].held)
        return static_cast<int>(i);
    const std::int64_t left = deadline_ns - base::monotonic_ns();
    if (left <= 0)
      return -1;
    released_.wait_for(lock, std::chrono::nanoseconds(left));
  }
}

std::span<std::uint8_t> BufferRing::bytes(int index) const {
  return {slots_[static_cast<std::size_t>(index)].data.get(), bytes_};
}

void BufferRing::hold(int index, std::uint64_t sequence) {
  const std::lock_guard lock(mutex_);
  Slot &slot = slots_[static_cast<std::size_t>(index)];
  slot.held = true;
  slot.sequence = sequence;
}

void BufferRing::release(int index, std::uint64_t sequence) {
  {
    const std::lock_guard lock(mutex_);
    if (index < 0 || static_cast<std::size_t>(index) >= slots_.size())
      return;
    Slot &slot = slots_[static_cast<std::size_t>(index)];
    if (!slot.held || slot.sequence != sequence)
      return;
    slot.held = false;
  }
  released_.notify_all();
}

} // namespace camhead::hal::camera
