// The one interface every output backend implements: the V4L2 loopback
// webcam, DRM/KMS (HDMI), a Y4M file or PNG sequence, and the null sink for
// benchmarks. A board file or `camhead run --output URI` chooses which.
//
// A frame goes out in two steps so that the renderer writes straight into
// the backend's memory (a mapped V4L2 buffer, a DRM dumb buffer): acquire()
// lends a buffer of frame_bytes(format()) bytes, submit() sends what was
// written into it. As hal/camera, a backend never throws once opened: a
// write that fails, or a device that went away, is a status, and the frame
// loop goes on.
//
// Thread safety: one thread calls acquire(), submit() and close(); status()
// from any thread.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "camhead/base/video_format.h"

namespace camhead::hal::output {

struct SinkStatus {
  bool connected = false;
  std::uint64_t frames = 0; // submitted successfully
  std::uint64_t errors = 0; // submissions that failed
  std::string detail;       // last error or state, human readable, names the device or file
};

class FrameSink {
public:
  virtual ~FrameSink() = default;
  FrameSink() = default;
  FrameSink(const FrameSink &) = delete;
  FrameSink &operator=(const FrameSink &) = delete;

  // Who this is, for messages: "v4l2 /dev/video10", "file out.y4m", "null".
  [[nodiscard]] virtual std::string name() const = 0;

  // The format the sink takes, fixed when it was opened.
  [[nodiscard]] virtual base::VideoFormat format() const = 0;

  // A buffer to write the next frame into, valid until submit(); empty when
  // the sink has none to lend now (the frame is skipped and counted).
  [[nodiscard]] virtual std::span<std::uint8_t> acquire() = 0;

  // Sends the acquired buffer. `capture_ns` is the camera timestamp of the
  // frame it shows (for sinks that carry timestamps). False on failure, with
  // the reason in status().detail.
  virtual bool submit(std::int64_t capture_ns) = 0;

  // Finishes the output: a file is completed and put in place, a device is
  // left showing a sane picture. Called once, after the last submit(); false
  // on failure, with the reason in status().detail.
  virtual bool close() = 0;

  [[nodiscard]] virtual SinkStatus status() const = 0;
};

} // namespace camhead::hal::output
