// Finds and opens libcamhead_markers.so (marker_tracker.h), as the libcamera
// camera's loader does: $CAMHEAD_MARKERS_MODULE, beside the executable, the
// install's lib folder, then the library path. No OpenCV header here.
#include <string>

#include "camhead/hal/module_loader.h"
#include "marker_module_abi.h"
#include "marker_tracker.h"

namespace camhead::pipeline {
namespace {

constexpr const char *kModuleName = CAMHEAD_MARKERS_MODULE_NAME;
// The Debian package whose library the module needs at run time.
constexpr const char *kOpenCvPackage = "libopencv-contrib406";

// Opened once and never closed: its trackers run its code until the end.
marker_module::Module &module() {
  static hal::ModuleOnce<marker_module::Module> once;
  const hal::ModuleSearch search =
      hal::module_search("CAMHEAD_MARKERS_MODULE", kModuleName, CAMHEAD_MARKERS_MODULE_RELDIR);
  hal::LoadedModule<marker_module::Module> loaded;
  if (marker_module::Module *opened = once.get(
          [&] {
            return hal::load_module<marker_module::Module>(
                search, kModuleName, kOpenCvPackage, marker_module::kFactorySymbol,
                marker_module::kAbiVersion, "its markers module");
          },
          loaded))
    return *opened;
  const std::string &last_error = loaded.error;
  if (!last_error.empty())
    throw MarkerModuleError("marker tracking: " + last_error);
  throw MarkerModuleError(
      std::string("marker tracking: ") + kModuleName + " is not in " + search.searched +
      ": camhead builds it where libopencv-contrib-dev is installed (cmake/bootstrap.sh "
      "installs it), and it needs the Debian package " +
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
