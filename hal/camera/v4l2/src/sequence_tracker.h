// The driver's 32-bit buffer sequence numbers as camhead's frame numbers:
// strictly increasing from 0 across reopens, with the frames the driver made
// and nobody dequeued counted as dropped. A number that repeats or goes back
// (v4l2loopback 0.12.7 leaves it 0 for mmap writers; a driver restarts at 0
// after STREAMON) is the next frame, not 4 billion lost ones.
//
// Thread safety: none; the capture thread owns it.
#pragma once

#include <cstdint>

namespace camhead::hal::camera {

class SequenceTracker {
public:
  struct Step {
    std::uint64_t sequence = 0; // camhead's number for this frame
    std::uint64_t dropped = 0;  // frames lost just before it
  };

  [[nodiscard]] Step next(std::uint32_t driver_sequence);

  // A new stream (the device was reopened): its first number counts from
  // the last frame without a gap.
  void restart() { have_last_ = false; }

private:
  bool have_last_ = false;
  std::uint32_t last_ = 0;
  std::uint64_t next_ = 0;
};

} // namespace camhead::hal::camera
