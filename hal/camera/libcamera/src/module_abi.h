// What the loader (libcamera_loader.cpp, linked into camhead) and the module
// (libcamhead_libcamera.so, which links libcamera) agree on: one extern "C"
// factory returning a table of virtual functions. Both sides are built from
// the same tree by the same compiler, so C++ types cross; exceptions do not
// (the module answers with an error string), and kAbiVersion changes
// whenever this header does, so that a stale module from an older build is
// refused rather than called with another layout.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "camhead/hal/camera/camera_source.h"
#include "camhead/hal/camera/libcamera/libcamera_camera.h"

namespace camhead::hal::camera::libcamera_module {

inline constexpr int kAbiVersion = 1;
inline constexpr const char *kFactorySymbol = "camhead_libcamera_module";

class Module {
public:
  // The cameras, "'MODEL' (ID)"; sets `error` instead where libcamera fails.
  virtual std::vector<std::string> list_cameras(std::string &error) = 0;
  // A streaming camera, or null with `error` saying why.
  virtual std::unique_ptr<CameraSource> open(const LibcameraCameraOptions &options,
                                             std::string &error) = 0;

protected:
  // The module owns its one instance; the loader never deletes it.
  ~Module() = default;
};

// The factory's type: the module's instance for `abi_version`, or null when
// the module was built for another one.
using Factory = Module *(*)(int abi_version);

} // namespace camhead::hal::camera::libcamera_module
