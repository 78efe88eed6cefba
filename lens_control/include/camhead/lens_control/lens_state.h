// The plain value types of the lens chain: what an encoder reports (counts),
// what the filters and the time alignment make of it (counts at an instant),
// and the physical lens state the renderer's thin-lens camera consumes.
//
// Everything here is a value type without behaviour beyond small helpers, so
// that pipeline/ can copy it across threads and modules by value.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>

namespace camhead::lens_control {

// One reading from a lens-encoder source. t_ns is on the monotonic clock
// (CLOCK_MONOTONIC) as stamped by the source; an axis that the source does not
// report in this sample (absent, or dropped out) is empty. An axis may come
// as raw counts, as the physical value the source already knows (a trace's
// focus_m column, OpenTrackIO's focusDistance), or both: LensTracker says
// which it takes.
struct EncoderSample {
  std::int64_t t_ns = 0;
  std::optional<std::int32_t> focus, iris, zoom;
  // Metres from the entrance pupil (+infinity allowed), the f-number, mm.
  std::optional<double> focus_distance_m, f_number, focal_length_mm;
};

// One axis sample inside the chain: raw counts after spike rejection, or
// filtered counts, at the time the source stamped them.
struct TimedCounts {
  std::int64_t t_ns = 0;
  double counts = 0.0;
};

// One axis after filtering and time alignment: counts are real-valued because
// filtering and interpolation land between integer counts.
struct AxisReading {
  double counts = 0.0;
  std::int64_t t_ns = 0; // the instant this reading describes
  bool fresh = false;    // false when held or extrapolated past its bound
};

// The three axes at one instant; an axis the rig has no encoder for is empty.
struct LensCounts {
  std::optional<AxisReading> focus, iris, zoom;
};

// Axes known at one instant as physical values instead of counts, in the
// spaces they are interpolated in: focus in diopters (1/m, infinity = 0),
// the iris in stops (2 log2 N), the focal length as ln(mm). AxisReading's
// `counts` holds the value.
struct LensValues {
  std::optional<AxisReading> focus_diopters, iris_stops, log_focal_length;
};

// A physical quantity with the instant it describes and whether the data
// behind it is current. `clamped` says the encoder was outside the profile's
// calibrated range and the value is the nearest table end.
struct Measured {
  double value = 0.0;
  std::int64_t t_ns = 0;
  bool fresh = false;
  bool clamped = false;
};

// Brown-Conrady coefficients in the OpenCV order and convention (normalised
// image coordinates, radial k1 k2 k3, tangential p1 p2).
struct Distortion {
  double k1 = 0.0, k2 = 0.0, k3 = 0.0, p1 = 0.0, p2 = 0.0;
};

// Where the lens's image is centred and how its pixels are shaped, beyond
// the image scale (version 3 profiles; the ideal otherwise): the principal
// point as a fraction of the image's width and height from its top-left
// corner, pixel x spanning [x, x + 1) (the renderer's convention: OpenCV's
// cx, with pixel centres at integers, is principal_x * width - 0.5), and
// the focal length down the image over the one across it.
struct LensProjection {
  double principal_x = 0.5, principal_y = 0.5;
  double fy_over_fx = 1.0;
};

struct LensState {
  // Metres from the entrance pupil; +infinity when focused at infinity.
  Measured focus_distance_m;
  Measured f_number;
  // Only when the profile gives T-stops.
  std::optional<Measured> t_stop;
  // Nominal focal length of the zoom position (mm).
  Measured focal_length_mm;
  // Effective projection focal length at this zoom and focus (focus
  // breathing): the pinhole focal length that reproduces the image scale.
  // Equal to focal_length_mm when the profile has no breathing data.
  Measured projection_focal_length_mm;
  // Entrance-pupil position along the optical axis, mm in front of the
  // profile's reference plane (positive towards the scene).
  Measured entrance_pupil_offset_mm;
  std::optional<Distortion> distortion;
  LensProjection projection;
  // False for LensProfile::uncalibrated(): the values are a nominal lens, not
  // this lens, and the renderer's depth of field will not match the plate.
  bool calibrated = false;

  [[nodiscard]] bool all_fresh() const {
    return focus_distance_m.fresh && f_number.fresh && focal_length_mm.fresh &&
           projection_focal_length_mm.fresh && entrance_pupil_offset_mm.fresh &&
           (!t_stop || t_stop->fresh);
  }
};

// Full field of view (radians) across a sensor dimension (mm), from the
// effective projection focal length, so it includes focus breathing.
[[nodiscard]] inline double field_of_view_rad(const LensState &s, double sensor_size_mm) {
  return 2.0 * std::atan(0.5 * sensor_size_mm / s.projection_focal_length_mm.value);
}

} // namespace camhead::lens_control
