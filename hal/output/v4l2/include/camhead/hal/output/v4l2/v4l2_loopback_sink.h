// Output to a v4l2loopback device: camhead's composite as a webcam that
// Chrome, OBS, ffmpeg and video-call programs open like any other.
//
// Open: the node must offer video output (VIDIOC_QUERYCAP): with
// exclusive_caps=1 it does only while no other program writes to it.
// VIDIOC_S_FMT (VIDEO_OUTPUT) sets the format with sizeimage exactly one
// frame; the driver must answer that format and size (a device kept at
// another format by its readers fails, naming both). VIDIOC_S_PARM sets the
// rate readers are told where the driver takes it (Debian's 0.12.7 does not
// always; not fatal, status().detail says so). VIDIOC_STREAMON (OUTPUT) on
// the same descriptor, which makes it the device's writer. Anything that
// fails there throws V4l2SinkError "DEVICE: REASON".
//
// Frames go out with one write() each, of exactly frame_bytes(format())
// bytes, on the descriptor that set the format: v4l2loopback counts one
// write() as one frame, stamps it on CLOCK_MONOTONIC and sets its sequence
// number and bytesused (Chrome drops frames whose bytesused is short). This
// is what ffmpeg's v4l2 output does. The mmap OUTPUT path of 0.12.7 was
// not taken: it hands the writer the buffer readers were last given (so a
// frame is overwritten while it is being read) and leaves every sequence
// number 0. The cost is one copy of each frame into the driver.
// capture_ns is therefore not passed on.
//
// Loss: a write failing with ENODEV (the module unloaded) marks the sink
// disconnected; submit() then tries to reopen the device every 0.25 s, and
// skips the frames until it is back.
//
// close(): writes one black frame, so that readers are left with a neutral
// picture rather than the last composite frozen (or the green of a
// zero-filled frame), then closes the descriptor, which gives the output
// back to the next writer (with exclusive_caps=1 only a writer that called
// STREAMON does that in 0.12.7).
//
// Thread safety: as FrameSink (submit and close from one thread; status
// from any).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "camhead/base/video_format.h"
#include "camhead/hal/output/frame_sink.h"

namespace camhead::hal::output {

// "DEVICE: REASON", thrown by open_v4l2_loopback_sink only.
class V4l2SinkError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// `format`: yuyv (what Chrome prefers) or nv12, stride 0 (packed; a driver
// that pads rows sets format().stride). `fps`: 0.01 to 1000.
[[nodiscard]] std::unique_ptr<FrameSink>
open_v4l2_loopback_sink(const std::string &device, base::VideoFormat format, double fps);

} // namespace camhead::hal::output
