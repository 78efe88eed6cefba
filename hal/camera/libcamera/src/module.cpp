// libcamhead_libcamera.so's one entry point (module_abi.h): the factory the
// loader in camhead looks up by name. Everything else in the module is
// hidden (-fvisibility=hidden), so that its copies of camhead's code and
// libcamera's symbols never meet the executable's.
#include <exception>

#include "libcamera_source.h"
#include "module_abi.h"

namespace camhead::hal::camera {
namespace {

class LibcameraModule final : public libcamera_module::Module {
public:
  std::vector<std::string> list_cameras(std::string &error) override {
    try {
      return camera::list_cameras(error);
    } catch (const std::exception &e) {
      error = std::string("libcamera: ") + e.what();
      return {};
    }
  }

  std::unique_ptr<CameraSource> open(const LibcameraCameraOptions &options,
                                     std::string &error) override {
    // Nothing may cross back into camhead as an exception (module_abi.h).
    try {
      return open_libcamera_source(options, error);
    } catch (const std::exception &e) {
      error = std::string("libcamera: ") + e.what();
      return nullptr;
    }
  }
};

} // namespace
} // namespace camhead::hal::camera

extern "C" __attribute__((visibility("default"))) camhead::hal::camera::libcamera_module::Module *
camhead_libcamera_module(int abi_version) {
  static camhead::hal::camera::LibcameraModule module;
  return abi_version == camhead::hal::camera::libcamera_module::kAbiVersion ? &module : nullptr;
}
