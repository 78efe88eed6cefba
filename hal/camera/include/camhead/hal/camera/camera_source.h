// The one interface every camera backend implements: V4L2, libcamera, an
// image sequence or Y4M file, and the simulated camera. A board file chooses
// which (pipeline/ builds them); nothing above hal/ knows which it has.
//
// Pull model, as hal/lens: the capture thread calls wait_frame() in a loop.
// A backend never blocks past the timeout it is given and never throws once
// opened: a camera that went away is a status (`disconnected`), and the
// backend keeps trying to take it up again on later calls. A frame's bytes
// belong to the backend and stay valid, untouched, until release() is called
// with that frame (a V4L2 buffer is queued again, a libcamera Request reused);
// a backend has a fixed number of buffers, so a caller that holds them all
// gets no new frame until it gives one back. Callers hold frames through a
// FrameLease (frame_lease.h), which gives each back once, on every path.
//
// Thread safety: wait_frame() from one thread; release() and status() from
// any thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <string>

#include "camhead/base/video_format.h"

namespace camhead::hal::camera {

// What a frame's timestamp marks (V4L2_BUF_FLAG_TSTAMP_SRC_SOE / _EOF).
enum class TimestampMark { start_of_exposure, end_of_frame };

struct CapturedFrame {
  base::VideoFormat format;
  std::span<const std::uint8_t> bytes; // frame_bytes(format) of them
  std::uint64_t sequence = 0;          // the source's frame counter; gaps are drops
  std::int64_t timestamp_ns = 0;       // CLOCK_MONOTONIC (base/monotonic_clock.h)
  TimestampMark mark = TimestampMark::start_of_exposure;
  std::int64_t exposure_ns = 0; // 0 where the source does not say
  int buffer = -1;              // the backend's own handle, for release()
};

// The instant the frame's exposure is half done: what its lens state must
// describe (lens_control's time alignment). An end-of-frame stamp is taken as
// the end of the exposure (rolling-shutter readout is not modelled).
[[nodiscard]] inline std::int64_t mid_exposure_ns(const CapturedFrame &frame) {
  return frame.mark == TimestampMark::start_of_exposure
             ? frame.timestamp_ns + frame.exposure_ns / 2
             : frame.timestamp_ns - frame.exposure_ns / 2;
}

enum class CaptureResult {
  frame,        // `out` holds a frame; release() it when done
  timeout,      // nothing within the timeout
  disconnected, // the camera is gone; later calls try to take it up again
  ended,        // a file played once is over
  failed,       // a file played once broke off (a frame that cannot be read); status().detail
                // names the file and frame; no frame follows
};

// Health of a camera, for the status line, statistics and logs.
struct CameraStatus {
  bool connected = false;
  std::uint64_t frames = 0;     // delivered through wait_frame()
  std::uint64_t dropped = 0;    // gaps in the sequence: frames the camera made and we lost
  std::uint64_t errors = 0;     // buffers the driver flagged as corrupt (not delivered)
  std::uint64_t reconnects = 0; // times the camera came back after going away
  std::string detail;           // last error or state, human readable, names the device
};

class CameraSource {
public:
  virtual ~CameraSource() = default;
  CameraSource() = default;
  CameraSource(const CameraSource &) = delete;
  CameraSource &operator=(const CameraSource &) = delete;

  // Who this is, for messages: "v4l2 /dev/video0", "file take1.y4m", "sim".
  [[nodiscard]] virtual std::string name() const = 0;

  // The format frames come in, fixed when the backend was opened.
  [[nodiscard]] virtual base::VideoFormat format() const = 0;

  // The nominal time between frames (the camera's rate), 0 where unknown.
  [[nodiscard]] virtual std::int64_t frame_interval_ns() const = 0;

  // Waits at most `timeout` for the next frame.
  [[nodiscard]] virtual CaptureResult wait_frame(std::chrono::milliseconds timeout,
                                                 CapturedFrame &out) = 0;

  // Gives a frame's buffer back; each delivered frame exactly once.
  virtual void release(const CapturedFrame &frame) = 0;

  [[nodiscard]] virtual CameraStatus status() const = 0;
};

} // namespace camhead::hal::camera
