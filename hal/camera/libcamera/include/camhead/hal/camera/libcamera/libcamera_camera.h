// A camera that libcamera drives (a Raspberry Pi or Rockchip sensor through
// its ISP, a UVC webcam, vimc in the hardware lab) as a CameraSource.
//
// libcamera is not linked into camhead: the backend is a module,
// libcamhead_libcamera.so, built beside build/camhead where libcamera-dev is
// installed and opened here at run time, so that camhead keeps needing only
// Vulkan and the C++ runtime (README) and starts on a machine without
// libcamera. The module is looked for in $CAMHEAD_LIBCAMERA_MODULE (a full
// path) when that is set, else next to the running executable, in
// ../lib/camhead beside it (where cmake --install puts it), and in the
// library path. A module that is missing or cannot load (libcamera.so.0.0.3
// absent: Debian package libcamera0.0.3) makes open and list throw
// LibcameraCameraError naming the module and the package.
//
// Open: one camera by id (empty: the first listed), one stream of role
// VideoRecording with the wanted pixel format and size, validated; a
// configuration libcamera adjusts to another format or size fails, naming
// the camera and both configurations ("... asked 640x480 RGB888 (camhead
// bgr24), the camera gives 636x480 RGB888 (camhead bgr24)"). A changed
// buffer count or stride is taken. Buffers come from FrameBufferAllocator,
// mmapped once; one Request per buffer, all queued at start.
//
// Frames: each completed Request becomes a frame, released with release(),
// which reuses the Request and queues it again (from any thread). The stamp
// is controls::SensorTimestamp (CLOCK_MONOTONIC, start of exposure), else
// the buffer's own (status().detail says so); exposure_ns is
// controls::ExposureTime where the pipeline reports it (pipelines with an
// ISP), else 0. Frames whose buffer did not complete successfully, or hold
// less than a frame, are counted as errors and queued again; gaps in the
// buffers' sequence numbers are counted as dropped.
//
// Loss: the camera's disconnected signal, or the manager's cameraRemoved for
// its id, makes wait_frame() answer `disconnected`; later calls look the id
// up again every 0.5 s (a replugged webcam comes back as a new Camera with
// the same id) and count a reconnect when it streams again. Frames the
// caller still holds stay readable until released. libcamera 0.0.3 watches
// for unplugs only on UVC webcams; another pipeline whose device goes away
// just stops delivering (wait_frame() times out).
//
// Logging: libcamera's own messages go to stderr at its default level;
// LIBCAMERA_LOG_LEVELS=*:WARN quiets them.
//
// Thread safety: as CameraSource (wait_frame from one thread, release and
// status from any). open and list from any thread; they share one
// libcamera::CameraManager, which libcamera allows only one of per process.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/base/video_format.h"
#include "camhead/hal/camera/camera_source.h"

namespace camhead::hal::camera {

struct LibcameraCameraOptions {
  // libcamera's id ("platform/vimc.0 Sensor B", "/base/soc/i2c0mux/i2c@1/imx477@1a");
  // empty: the first camera libcamera lists.
  std::string camera_id;
  // yuyv, nv12, rgb24 (libcamera BGR888) or bgr24 (libcamera RGB888).
  base::PixelFormat format = base::PixelFormat::yuyv;
  int width = 0;
  int height = 0;
  // Buffers to ask for, 2 to 8; the pipeline may set its own count.
  int buffers = 4;
};

// "CAMERA: REASON" or "libcamera: REASON", thrown by open and list only.
class LibcameraCameraError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

[[nodiscard]] std::unique_ptr<CameraSource>
open_libcamera_camera(const LibcameraCameraOptions &options);

// The cameras libcamera finds, one line each: "'MODEL' (ID)", as `cam -l`
// prints them; empty when there are none.
[[nodiscard]] std::vector<std::string> list_libcamera_cameras();

// The module's file name, for messages: "libcamhead_libcamera.so".
[[nodiscard]] const char *libcamera_module_name();

} // namespace camhead::hal::camera
