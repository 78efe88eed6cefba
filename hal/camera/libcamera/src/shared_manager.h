// The module's one libcamera::CameraManager, shared by the cameras it opened
// and by listing: libcamera allows one per process (a second aborts), and
// starting one enumerates every media device, which is slow.
//
// Thread safety: any thread. The manager is started on first use and
// stopped when the last holder lets it go.
#pragma once

#include <memory>
#include <string>

#include <libcamera/camera_manager.h>

namespace camhead::hal::camera {

// The running manager, or null with `error` saying why it did not start.
[[nodiscard]] std::shared_ptr<libcamera::CameraManager> shared_camera_manager(std::string &error);

} // namespace camhead::hal::camera
