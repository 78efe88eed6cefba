// The simulated camera: a camera's timing, buffers and faults, with the
// picture made by a generator the caller supplies (pipeline/ renders the
// board's real-world scene with the lens of each exposure; tests draw
// patterns). The code above it, the capture thread and the run loop, cannot
// tell it from a V4L2 camera: frames come at the camera's rate, each exposure
// is stamped at its start on CLOCK_MONOTONIC, a frame the consumer was too
// slow for is lost as a sequence gap, and the camera can be made to go away
// and come back.
//
// Thread safety: as CameraSource; the generator runs on the thread that
// calls wait_frame().
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>

#include "camhead/base/video_format.h"
#include "camhead/hal/camera/camera_source.h"

namespace camhead::hal::camera {

// Draws the exposure [start_ns, start_ns + exposure_ns) into `out`,
// frame_bytes(format) bytes. Must not throw.
using FrameGenerator = std::function<void(std::int64_t start_ns, std::int64_t exposure_ns,
                                          std::span<std::uint8_t> out)>;

struct SimulatedCameraOptions {
  base::VideoFormat format{base::PixelFormat::yuyv, 720, 576};
  double fps = 25.0;
  // Real time: frame k's exposure starts at start + k / fps and is delivered
  // once it has ended and been drawn; a frame not taken by the time the next
  // one is complete is lost (counted dropped). Otherwise frames come as fast
  // as they are taken, stamped exactly 1 / fps apart from the first call:
  // reproducible runs for tests and for rendering a video offline.
  bool realtime = true;
  // Exposure per frame; 0 = half the frame interval (a 180-degree shutter).
  std::int64_t exposure_ns = 0;
  int buffers = 4;
  // Fault: after this many frames the camera is gone for `disconnect_s`
  // (wait_frame answers disconnected), then comes back on its own.
  std::optional<std::uint64_t> disconnect_after_frames;
  double disconnect_s = 1.0;
  // ... or, silent, it only stops sending (wait_frame times out, the status
  // stays connected), as a capture card that lost its signal does.
  bool disconnect_silently = false;
  // Warm-up (real time only): as it opens, the camera has the generator
  // draw this many exposures one frame interval apart from an instant
  // chosen then, and its frames keep to that grid (each exposure starts a
  // whole number of intervals after it). A generator whose pictures repeat
  // every warm_up_frames intervals and that keeps what it drew (the
  // simulated world: pipeline/run/rig_setup.cpp) then has every picture at
  // hand from the first frame, which comes at the camera's rate.
  // `warm_up_progress` hears each exposure drawn.
  std::uint64_t warm_up_frames = 0;
  std::function<void(std::uint64_t drawn, std::uint64_t of)> warm_up_progress;
};

// Throws std::invalid_argument for a format check_video_format() refuses, a
// rate that is not > 0 and finite, or fewer than 2 buffers.
[[nodiscard]] std::unique_ptr<CameraSource> open_simulated_camera(SimulatedCameraOptions options,
                                                                  FrameGenerator generator);

} // namespace camhead::hal::camera
