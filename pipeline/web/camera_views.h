// The operator page's camera-calibration helper: the camera frame as it
// came, its luma plane (tracking/luma.h: what the marker tracker and
// `camhead calibrate camera` read of a picture; stretched to the full range
// by the page where the camera's is limited) saved as an 8-bit grey PNG in
// a folder per lens position,
//   RECORDINGS/camera-views/focus-COUNTS[-zoom-COUNTS]/view-NNN.png,
// so that the views of one calibration (taken at one focus, as the fit
// needs) are the files of one folder, and the command that fits them can
// be named. Written as view-NNN.png.partial and renamed whole. The page's
// thread saves; the frame loop only copies the frame (web_feed.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "tracking/marker_tracker.h"

namespace camhead::pipeline::web {

// Where the lens is: its encoder counts now (none: not known).
struct LensPlace {
  std::optional<std::int32_t> focus, zoom;
};

struct SavedView {
  std::filesystem::path file; // absolute
  int views = 0;              // PNG views in its folder now, this one included
  std::string at;             // calibrate camera's --at: "focus=9400" or "focus=9400,zoom=120"
};

// Saves `luma` (a camera frame's, tracking/luma.h) as the next view of
// `place`'s folder under `recordings`. The error, or "" with `saved`
// filled. Needs the focus counts (the fit is made at one focus).
[[nodiscard]] std::string save_camera_view(const std::filesystem::path &recordings,
                                           const LumaImage &luma, const LensPlace &place,
                                           SavedView &saved);

} // namespace camhead::pipeline::web
