// A driver's 32-bit frame counter (a V4L2 buffer's sequence, libcamera's
// FrameMetadata::sequence, which is the same counter underneath) as
// camhead's frame numbers: strictly increasing from 0 across reopens, with
// the frames the camera made and nobody got counted as dropped. A number
// that repeats or goes back (v4l2loopback 0.12.7 leaves it 0 for mmap
// writers; a driver restarts at 0 after STREAMON) is the next frame, not 4
// billion lost ones. Shared by the V4L2 and libcamera backends.
//
// Thread safety: none; the capture thread owns it.
#pragma once

#include <cstdint>

namespace camhead::hal::camera {

class FrameSequence {
public:
  struct Step {
    std::uint64_t sequence = 0; // camhead's number for this frame
    std::uint64_t dropped = 0;  // frames lost just before it
  };

  [[nodiscard]] Step next(std::uint32_t driver_sequence) {
    Step step;
    if (have_last_) {
      // Modulo 2^32, so that the counter wrapping is one step.
      const std::uint32_t delta = driver_sequence - last_;
      if (delta != 0 && delta < 0x8000'0000u) {
        step.dropped = delta - 1;
        next_ += step.dropped;
      }
    }
    have_last_ = true;
    last_ = driver_sequence;
    step.sequence = next_++;
    return step;
  }

  // A new stream (the device was reopened, the camera started again): its
  // first number follows the last frame without a gap.
  void restart() { have_last_ = false; }

private:
  bool have_last_ = false;
  std::uint32_t last_ = 0;
  std::uint64_t next_ = 0;
};

} // namespace camhead::hal::camera
