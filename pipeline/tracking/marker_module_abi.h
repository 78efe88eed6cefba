// What the loader (marker_loader.cpp, in camhead) and the module
// (libcamhead_markers.so, which links OpenCV) agree on: one extern "C"
// factory returning a table of virtual functions, as the libcamera module
// does (hal/camera/libcamera/src/module_abi.h). Exceptions do not cross;
// kAbiVersion changes whenever this header or marker_tracker.h does.
#pragma once

#include <memory>
#include <string>

#include "marker_tracker.h"

namespace camhead::pipeline::marker_module {

inline constexpr int kAbiVersion = 6;
inline constexpr const char *kFactorySymbol = "camhead_markers_module";

class Module {
public:
  // A tracker for `board`, or null with `error` saying why.
  virtual std::unique_ptr<MarkerTracker> open(const MarkerBoard &board, std::string &error) = 0;
  // calibrate_camera() (marker_tracker.h): false with `error` saying why.
  virtual bool calibrate(const MarkerBoard &board, const std::vector<LumaImage> &views,
                         CameraCalibration &out, std::string &error) = 0;
  // draw_board_page() (marker_tracker.h): false with `error` saying why.
  virtual bool draw(const MarkerBoard &board, int pixels_per_square, BoardPage &out,
                    std::string &error) = 0;

protected:
  ~Module() = default; // the module owns its one instance
};

using Factory = Module *(*)(int abi_version);

} // namespace camhead::pipeline::marker_module
