// The buffers' sequence numbers (FrameMetadata::sequence, the V4L2 driver's
// 32-bit counter under libcamera) as camhead's frame numbers: increasing
// from 0 across reconnects, with the frames the camera made and nobody got
// counted as dropped. A number that repeats or goes back (the driver starts
// again at 0 after a restart) is the next frame, not 4 billion lost ones.
//
// Thread safety: none; the capture thread owns it.
#pragma once

#include <cstdint>

namespace camhead::hal::camera::libcamera_settings {

class SequenceGaps {
public:
  struct Step {
    std::uint64_t sequence = 0; // camhead's number for this frame
    std::uint64_t dropped = 0;  // frames lost just before it
  };

  [[nodiscard]] Step next(std::uint32_t camera_sequence);

  // A new stream (the camera was started again): its first number follows
  // the last frame without a gap.
  void restart() { have_last_ = false; }

private:
  bool have_last_ = false;
  std::uint32_t last_ = 0;
  std::uint64_t next_ = 0;
};

} // namespace camhead::hal::camera::libcamera_settings
