// Where `camhead calibrate camera` puts what it fitted: a camera point
// (lens_control/README.md, profile version 3) in a lens profile's text, at
// the focus (and zoom point) the views were taken at. The profile becomes
// version 3 if it was not: the image the views were in and the sensor's
// width join it, its top-level distortion goes (the camera points carry
// it), and the zoom point's breathing table goes (the points' fx is the
// image scale). The point replaces one at the same focus distance.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>

#include "tracking/marker_tracker.h"

namespace camhead::pipeline {

// Why a calibration cannot go into a profile; the message names the option
// or the profile's field.
class CameraProfileError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

struct CameraPointPlace {
  double focus_counts = 0.0;
  std::optional<double> zoom_counts; // a zoom lens's zoom point, by its counts
  // The sensor's width; for a profile that has none yet (not version 3).
  std::optional<double> sensor_width_mm;
  int width_px = 0, height_px = 0; // the views'
};

// The profile text `profile` (read from `source`, already a valid profile)
// with `camera` at `place`, as JSON text. Throws CameraProfileError.
[[nodiscard]] std::string profile_with_camera(const std::string &profile, const std::string &source,
                                              const CameraPointPlace &place,
                                              const CameraModel &camera);

} // namespace camhead::pipeline
