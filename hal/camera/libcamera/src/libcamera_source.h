// Inside the module: the CameraSource over libcamera that
// libcamera_camera.h describes, and the camera listing.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "camhead/hal/camera/camera_source.h"
#include "camhead/hal/camera/libcamera/libcamera_camera.h"

namespace camhead::hal::camera {

// A streaming camera, or null with `error` naming the camera and the reason.
[[nodiscard]] std::unique_ptr<CameraSource>
open_libcamera_source(const LibcameraCameraOptions &options, std::string &error);

// "'MODEL' (ID)" per camera; `error` set where libcamera does not start.
[[nodiscard]] std::vector<std::string> list_cameras(std::string &error);

} // namespace camhead::hal::camera
