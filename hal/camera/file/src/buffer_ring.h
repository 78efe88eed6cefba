// The file camera's fixed frame buffers. The capture thread takes a free one,
// fills it and hands it out; any thread gives it back. A buffer remembers the
// sequence number of the frame it carries, so that a stale or repeated
// release cannot free a buffer that now carries a newer frame.
//
// Thread safety: wait_free, bytes and hold from the capture thread; release
// from any thread.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

namespace camhead::hal::camera {

class BufferRing {
public:
  // Throws std::bad_alloc.
  BufferRing(int count, std::size_t bytes);

  // A free buffer's index, waiting until `deadline_ns` (CLOCK_MONOTONIC) for
  // one to be released; -1 if none was.
  [[nodiscard]] int wait_free(std::int64_t deadline_ns);

  [[nodiscard]] std::span<std::uint8_t> bytes(int index) const;

  // The buffer now carries frame `sequence` and is out with the caller.
  void hold(int index, std::uint64_t sequence);

  // Frees `index` if it is out with frame `sequence`; ignores anything else.
  void release(int index, std::uint64_t sequence);

private:
  struct Slot {
    std::unique_ptr<std::uint8_t[]> data;
    bool held = false;
    std::uint64_t sequence = 0;
  };

  std::size_t bytes_;
  std::vector<Slot> slots_;
  std::mutex mutex_;
  std::condition_variable released_;
};

} // namespace camhead::hal::camera
