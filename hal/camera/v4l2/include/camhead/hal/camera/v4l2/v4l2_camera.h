// A V4L2 capture device as a CameraSource: a UVC webcam, an HDMI or SDI
// capture card, a loopback device, vivid in the hardware lab.
//
// Open: VIDIOC_QUERYCAP (a single-planar video capture node with streaming
// I/O), VIDIOC_S_FMT with the wanted format and size, which the driver must
// take as asked (another format, size or a field order that is not a whole
// frame fails, naming both), VIDIOC_S_PARM for the rate where the driver
// can set one, mmap buffers (REQBUFS), all queued, STREAMON. Anything that
// fails there throws V4l2CameraError "DEVICE: REASON", e.g.
// "/dev/video0: asked 1920x1080 YUYV, the driver answers 1280x720 YUYV".
//
// Frames: wait_frame() polls, then dequeues; each frame is released with
// release(), which queues its buffer again (from any thread). Its stamp is
// the buffer's, on CLOCK_MONOTONIC where the driver says so
// (V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC), marked start of exposure or end of
// frame as V4L2_BUF_FLAG_TSTAMP_SRC_* says; a driver that does not say
// which clock is judged by the value (buffer_timestamp.h), and
// status().detail names what was assumed. `sequence` counts on from the
// driver's sequence numbers; their gaps are counted as dropped. Buffers the
// driver marks V4L2_BUF_FLAG_ERROR, or that hold less than a frame, are
// counted as errors and queued again, never delivered. exposure_ns is
// V4L2_CID_EXPOSURE_ABSOLUTE where the driver has it, read at open and at
// most twice a second after (on UVC every read is a USB control transfer),
// else 0.
//
// Colour: the format's matrix and range follow the driver's ycbcr_enc and
// quantization, or its colorspace, else BT.601 limited up to 576 lines and
// BT.709 limited above (camhead/hal/v4l2/pixel_formats.h).
//
// Loss: an ioctl answering ENODEV (unplugged), or poll() reporting an error
// or a hang-up, closes the device and wait_frame() answers `disconnected`.
// Later calls reopen it by the name it was opened with (a /dev/v4l/by-id
// link finds a webcam on another /dev/videoN after a replug) every 0.25 s,
// with the same format, and count a reconnect when it is back. Frames the
// caller still holds stay readable until released. A reopen is a handful of
// ioctls, which on UVC can take longer than a short timeout.
//
// Thread safety: as CameraSource (wait_frame from one thread, release and
// status from any).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "camhead/base/video_format.h"
#include "camhead/hal/camera/camera_source.h"

namespace camhead::hal::camera {

struct V4l2CameraOptions {
  // /dev/videoN, or a udev link such as /dev/v4l/by-id/usb-...-video-index0.
  std::string device;
  // yuyv, nv12, rgb24 or bgr24; with `mjpeg`, rgb24 (the decoded frames).
  base::PixelFormat format = base::PixelFormat::yuyv;
  int width = 0;
  int height = 0;
  // 0: whatever rate the driver runs at; otherwise 0.01 to 1000, which a
  // driver that can set its rate must take (within 0.5 %).
  double fps = 0;
  // Buffers to ask for, 2 to 8; the driver may give more. 4 keeps one with
  // the caller, one with the renderer and two filling.
  int buffers = 4;
  // Ask the device for MJPEG (what most USB webcams give at 720p and above)
  // and deliver each frame decoded to rgb24 on the capture thread. A frame
  // that does not decode is counted as an error and not delivered.
  bool mjpeg = false;
};

// "DEVICE: REASON", thrown by open_v4l2_camera only.
class V4l2CameraError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

[[nodiscard]] std::unique_ptr<CameraSource> open_v4l2_camera(const V4l2CameraOptions &options);

} // namespace camhead::hal::camera
