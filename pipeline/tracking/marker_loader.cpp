// Finds and opens libcamhead_markers.so (marker_tracker.h), as the libcamera
// camera's loader does: $CAMHEAD_MARKERS_MODULE, beside the executable, the
// install's lib folder, then the library path. No OpenCV header here.
#include <memory>
#include <mutex>
#include <string>

#include "camhead/hal/module_search.h"
#include "camhead/hal/shared_library.h"
#include "marker_module_abi.h"
#include "marker_tracker.h"

namespace camhead::pipeline {
namespace {

constexpr const char *kModuleName = CAMHEAD_MARKERS_MODULE_NAME;
// The Debian package whose library the module needs at run time.
constexpr const char *kOpenCvPackage = "libopencv-contrib406";

// Opened once and never closed: its trackers run its code until the end.
marker_module::Module &module() {
  struct Opened {
    hal::SharedLibrary *library; // kept reachable, for leak checkers too
    marker_module::Module *module;
  };
  static std::mutex mutex;
  static const Opened *opened = nullptr;
  const std::lock_guard lock(mutex);
  if (opened != nullptr)
    return *opened->module;
  const hal::ModuleSearch search =
      hal::module_search("CAMHEAD_MARKERS_MODULE", kModuleName, CAMHEAD_MARKERS_MODULE_RELDIR);
  std::string last_error;
  for (const std::string &path : search.candidates) {
    auto library = std::make_unique<hal::SharedLibrary>(path, kOpenCvPackage);
    marker_module::Factory factory = nullptr;
    library->resolve(marker_module::kFactorySymbol, factory);
    if (!library->ok()) {
      last_error = library->error();
      if (path == kModuleName && hal::module_not_installed(last_error, kModuleName))
        last_error.clear();
      if (!last_error.empty())
        break;
      continue;
    }
    marker_module::Module *instance = factory(marker_module::kAbiVersion);
    if (instance == nullptr)
      throw MarkerModuleError(path + ": built for another camhead (module ABI " +
                              std::to_string(marker_module::kAbiVersion) +
                              " wanted); rebuild camhead and its markers module together");
    opened = new Opened{library.release(), instance}; // never closed: see above
    return *instance;
  }
  if (!last_error.empty())
    throw MarkerModuleError("marker tracking: " + last_error);
  throw MarkerModuleError(
      std::string("marker tracking: ") + kModuleName + " is not in " + search.searched +
      ": camhead builds it where libopencv-contrib-dev is installed (cmake/bootstrap.sh "
      "without --run installs it), and it "
      "needs the Debian package " +
      kOpenCvPackage + " to run");
}

} // namespace

const char *marker_module_name() {
  return kModuleName;
}

std::string marker_module_problem() {
  try {
    (void)module();
    return {};
  } catch (const MarkerModuleError &e) {
    return e.what();
  }
}

std::unique_ptr<MarkerTracker> open_marker_tracker(const MarkerBoard &board) {
  std::string error;
  std::unique_ptr<MarkerTracker> tracker = module().open(board, error);
  if (!tracker)
    throw MarkerModuleError(board.file.string() + ": " + error);
  return tracker;
}

CameraCalibration calibrate_camera(const MarkerBoard &board, const std::vector<LumaImage> &views) {
  std::string error;
  CameraCalibration out;
  if (!module().calibrate(board, views, out, error))
    throw MarkerModuleError(board.file.string() + ": " + error);
  return out;
}

BoardPage draw_board_page(const MarkerBoard &board, int pixels_per_square) {
  std::string error;
  BoardPage out;
  if (!module().draw(board, pixels_per_square, out, error))
    throw MarkerModuleError(board.file.string() + ": " + error);
  return out;
}

} // namespace camhead::pipeline
