// Finds and opens libcamhead_libcamera.so (libcamera_camera.h) and calls its
// factory. Linked into camhead, which must not need libcamera itself: this
// file includes no libcamera header.
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "camhead/hal/camera/libcamera/libcamera_camera.h"
#include "camhead/hal/module_search.h"
#include "camhead/hal/shared_library.h"
#include "module_abi.h"

namespace camhead::hal::camera {
namespace {

constexpr const char *kModuleName = CAMHEAD_LIBCAMERA_MODULE_NAME;
// The Debian package the module needs at run time (libcamera.so.0.0.3).
constexpr const char *kLibcameraPackage = "libcamera0.0.3";

// The module's factory table, opened once per file and never closed: the
// cameras it made run its code until the process ends.
libcamera_module::Module &module() {
  struct Opened {
    SharedLibrary *library; // kept reachable, for leak checkers too
    libcamera_module::Module *module;
  };
  static std::mutex mutex;
  static auto *const opened = new std::map<std::string, Opened>;
  const std::lock_guard lock(mutex);
  const ModuleSearch search =
      module_search("CAMHEAD_LIBCAMERA_MODULE", kModuleName, CAMHEAD_LIBCAMERA_MODULE_RELDIR);
  std::string last_error;
  // libcamera logs every start at INFO on stderr, into the middle of
  // camhead's own output, and reads its levels once, as it loads: warnings
  // and errors only, unless the user set LIBCAMERA_LOG_LEVELS.
  setenv("LIBCAMERA_LOG_LEVELS", "*:WARN", 0);
  for (const std::string &path : search.candidates) {
    if (const auto it = opened->find(path); it != opened->end())
      return *it->second.module;
    auto library = std::make_unique<SharedLibrary>(path, kLibcameraPackage);
    libcamera_module::Factory factory = nullptr;
    library->resolve(libcamera_module::kFactorySymbol, factory);
    if (!library->ok()) {
      last_error = library->error();
      // A bare name that dlopen did not find means the module is not
      // installed; a file that exists but does not load is worth its own
      // message (its libcamera is missing or another version).
      if (path == kModuleName && module_not_installed(last_error, kModuleName))
        last_error.clear();
      if (!last_error.empty())
        break;
      continue;
    }
    libcamera_module::Module *instance = factory(libcamera_module::kAbiVersion);
    if (instance == nullptr)
      throw LibcameraCameraError(path + ": built for another camhead (module ABI " +
                                 std::to_string(libcamera_module::kAbiVersion) +
                                 " wanted); rebuild camhead and its libcamera module together");
    opened->emplace(path, Opened{library.release(), instance}); // never closed: see above
    return *instance;
  }
  if (!last_error.empty())
    throw LibcameraCameraError("libcamera backend: " + last_error);
  throw LibcameraCameraError(
      std::string("libcamera backend: ") + kModuleName + " is not in " + search.searched +
      ": camhead builds it where libcamera-dev is installed (cmake/bootstrap.sh "
      "without --run installs it), and it "
      "needs the Debian package " +
      kLibcameraPackage + " to run");
}

} // namespace

const char *libcamera_module_name() {
  return kModuleName;
}

std::unique_ptr<CameraSource> open_libcamera_camera(const LibcameraCameraOptions &options) {
  std::string error;
  std::unique_ptr<CameraSource> camera = module().open(options, error);
  if (!camera)
    throw LibcameraCameraError(error);
  return camera;
}

std::vector<std::string> list_libcamera_cameras() {
  std::string error;
  std::vector<std::string> cameras = module().list_cameras(error);
  if (!error.empty())
    throw LibcameraCameraError(error);
  return cameras;
}

} // namespace camhead::hal::camera
