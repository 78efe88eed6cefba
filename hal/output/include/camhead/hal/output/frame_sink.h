// The one interface every output backend implements: the V4L2 loopback
// webcam, DRM/KMS (HDMI), a Y4M file or PNG sequence, and the null sink for
// benchmarks. A board file or `camhead run --output URI` chooses which.
//
// A frame goes out in one call, from memory the caller owns: the live
// pipeline's renderer writes each composite into a buffer of its own (a
// slot, one per output, that the output thread then hands over), and
// submit() sends it without copying it again where the backend can: the
// loopback and a file write() it as it is (a Y4M file by way of its planes,
// the one conversion its format needs), the null sink only counts it, and
// the DRM sink copies it into the dumb buffer it shows next, the one copy a
// display needs (its scanout memory is read while the next frame renders).
// A repeat of the last frame is the same buffer submitted again: no copy.
// As hal/camera, a backend never throws once opened: a write that fails, or
// a device that went away, is a status, and the frame loop goes on. The
// backends share that state machine (sink_base.h).
//
// Thread safety: one thread calls submit() and close(); status() from any
// thread.
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

  // Sends `frame`, frame_bytes(format()) bytes in format(); `capture_ns`
  // is the camera timestamp of the frame it shows (for sinks that carry
  // timestamps). The sink keeps no reference to `frame`. False when the
  // frame did not go out (a write failed, a device is away, the size is
  // wrong), with the reason in status().detail.
  virtual bool submit(std::span<const std::uint8_t> frame, std::int64_t capture_ns) = 0;

  // Finishes the output: a file is completed and put in place, a device is
  // left showing a sane picture. Called once, after the last submit(); false
  // on failure, with the reason in status().detail.
  virtual bool close() = 0;

  [[nodiscard]] virtual SinkStatus status() const = 0;
};

// Why `frame` is not a frame of `format` ("a frame of N bytes, not the M of
// FORMAT"); empty when it is.
[[nodiscard]] inline std::string wrong_frame_size(std::span<const std::uint8_t> frame,
                                                  const base::VideoFormat &format) {
  const std::size_t expected = base::frame_bytes(format);
  if (frame.size() == expected)
    return {};
  return "a frame of " + std::to_string(frame.size()) + " bytes, not the " +
         std::to_string(expected) + " of " + base::describe(format);
}

} // namespace camhead::hal::output
