// A lens profile: calibration tables from raw encoder counts to physical lens
// quantities, read from JSON (format in lens_control/README.md), and the
// uncalibrated fallback used when a rig has no profile for its lens.
//
// Each quantity is interpolated with PCHIP in the space where it is close to
// linear in ring rotation, so that a handful of calibration marks suffice:
//   focus        diopters, 1/distance (infinity = 0)
//   iris, T-stop stops, 2*log2(N)
//   focal length log(f)
// Focus breathing (projection focal length) is a table over focus distance
// (in diopters) per zoom calibration point, blended linearly in zoom counts
// between the two zoom points around the current zoom. The focus table is
// either one table for all zoom positions (format version 1) or, on a zoom
// whose focus scale shifts with focal length, one table per zoom point
// (version 2): the focus counts go through the two tables around the current
// zoom and their diopters are blended with the same weight as breathing.
// Version 3 adds the camera model OpenCV calibrates (fx fy cx cy and
// Brown-Conrady k1 k2 p1 p2 k3, in the pixels of the profile's image) as a
// table over focus per zoom point, interpolated in diopters and blended
// across zoom as breathing is; its fx sets the projection focal length.
// Tables that all run the same way (profile_reader checks) blend into a curve
// that runs that way too, so the focus never runs backwards at any zoom.
//
// Thread safety: immutable after construction; any thread may call const
// members concurrently.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "camhead/base/config_error.h"
#include "camhead/lens_control/lens_state.h"
#include "camhead/lens_control/monotone_curve.h"

namespace camhead::lens_control {

// A profile file that cannot be used. what() reads "FILE: FIELD: REASON", where
// FIELD is a JSON path such as focus[3].distance_m, or "(file)" / "(JSON)"
// when the file cannot be read or parsed (base/config_error.h).
class ProfileError : public base::ConfigError {
public:
  using base::ConfigError::ConfigError;
  explicit ProfileError(const base::ConfigError &e) : base::ConfigError(e) {}
};

class LensProfile {
public:
  // A value from one table lookup.
  struct Lookup {
    double value = 0.0;
    bool clamped = false; // counts outside the calibrated range: nearest end value
  };

  // Loads and validates a profile file. Throws ProfileError.
  [[nodiscard]] static LensProfile load(const std::filesystem::path &path);
  // Parses profile JSON text; errors name `source`. Throws ProfileError.
  [[nodiscard]] static LensProfile parse(std::string_view json_text,
                                         const std::filesystem::path &source);
  // The fallback when no profile is known: a nominal 35 mm f/2.8 lens focused
  // at infinity whatever the encoders say, flagged calibrated() == false and
  // named so in name() and in every LensState it produces.
  [[nodiscard]] static LensProfile uncalibrated();

  [[nodiscard]] const std::string &name() const { return name_; }
  [[nodiscard]] bool calibrated() const { return calibrated_; }
  [[nodiscard]] bool has_t_stop() const { return !t_stop_stops_.empty(); }
  [[nodiscard]] bool is_zoom() const { return zoom_counts_.size() > 1; }
  // One focus table per zoom point (format version 2) rather than one for all.
  [[nodiscard]] bool has_per_zoom_focus() const { return !zoom_points_.front().focus.empty(); }

  // Single lookups, for tests and calibration tools.
  // Focus at a zoom position. With per-zoom focus tables, `clamped` is also
  // set when the zoom is outside its calibrated range (the end table is used),
  // as for projection_focal_length_mm.
  [[nodiscard]] Lookup focus_distance_m(double zoom_counts, double focus_counts) const;
  // Focus at the first zoom point: the whole lens for a profile with one
  // focus table; with per-zoom tables, use the form above.
  [[nodiscard]] Lookup focus_distance_m(double focus_counts) const;
  [[nodiscard]] Lookup f_number(double iris_counts) const;
  [[nodiscard]] std::optional<Lookup> t_stop(double iris_counts) const;
  [[nodiscard]] Lookup focal_length_mm(double zoom_counts) const;
  [[nodiscard]] Lookup projection_focal_length_mm(double zoom_counts, double focus_counts) const;
  [[nodiscard]] Lookup entrance_pupil_offset_mm(double zoom_counts) const;
  [[nodiscard]] const std::optional<Distortion> &distortion() const { return distortion_; }
  // A camera model per zoom point (format version 3).
  [[nodiscard]] bool has_camera_model() const { return image_.has_value(); }

  // The full lens state for aligned counts. An axis without a reading takes
  // the lens's rest value, not fresh: focus at the far end of the table (of
  // each table, at the current zoom), iris wide open, zoom at its first
  // calibration point. With per-zoom focus tables the focus distance depends
  // on zoom too: as old as the older reading, fresh only if both are.
  // An axis in `values` (and not in `counts`) takes that value instead of
  // a lookup: the focal length as given (and the projection focal length
  // equal to it, the tables' breathing being over zoom counts), the f-number
  // as given (no T-stop), the focus as given (breathing from the tables at
  // the zoom there is). The state is calibrated if the profile is, or if
  // every axis came as a value.
  [[nodiscard]] LensState evaluate(const LensCounts &counts, const LensValues &values = {}) const;

  // OpenCV's camera parameters, in this order (CameraPoint's indices).
  enum CameraParam { kFx, kFy, kCx, kCy, kK1, kK2, kP1, kP2, kK3, kCameraParams };
  using CameraPoint = std::array<double, kCameraParams>;

private:
  friend class ProfileReader; // profile_reader.cpp fills the tables

  // The images a version 3 profile's camera tables were calibrated in, and
  // the width of the sensor they span (fx in millimetres).
  struct Image {
    int width_px = 0, height_px = 0;
    double sensor_width_mm = 0.0;
  };

  // The camera model of one zoom point over focus diopters (increasing);
  // one point serves every focus.
  struct CameraTable {
    std::vector<double> diopters;
    std::vector<CameraPoint> points;
    std::array<MonotoneCurve, kCameraParams> curves; // empty for one point
    [[nodiscard]] CameraPoint at(double diopters) const;
  };

  // One zoom calibration point (a prime has exactly one).
  struct ZoomPoint {
    double focal_length_mm = 0.0;
    double entrance_pupil_offset_mm = 0.0;
    // Projection focal length over focus diopters; empty = no breathing data.
    MonotoneCurve breathing;
    std::optional<double> projection_focal_length_mm; // when given as one value
    bool has_pupil = false, has_projection = false;   // as given in the file
    // Focus counts -> 1/m at this zoom (version 2); empty = the one
    // focus_diopters_ table serves every zoom.
    MonotoneCurve focus;
    std::optional<CameraTable> camera = std::nullopt; // version 3
  };

  // The two zoom points around a zoom position and the blending weight of the
  // second: zoom_points_[k] * (1 - t) + zoom_points_[k + 1] * t. Linear in
  // zoom counts; t is exactly 0 or 1 at a calibration point and at or beyond
  // the ends. For a prime, k = 0 and t = 0.
  struct ZoomSpan {
    std::size_t k = 0;
    double t = 0.0;
    bool clamped = false; // zoom counts outside the zoom table
  };
  [[nodiscard]] ZoomSpan zoom_span(double zoom_counts) const;

  // Focus in diopters at a zoom position, and the far end of the focus range
  // there (the rest value without a focus reading, never clamped).
  [[nodiscard]] MonotoneCurve::Result focus_diopters(double zoom_counts, double focus_counts) const;
  [[nodiscard]] MonotoneCurve::Result rest_focus_diopters(double zoom_counts) const;
  [[nodiscard]] Lookup projection_for_focus(double zoom_counts, MonotoneCurve::Result focus) const;
  [[nodiscard]] double rest_counts_iris() const;
  [[nodiscard]] double projection_at_point(const ZoomPoint &z, double diopters) const;
  // The camera model at a zoom position and focus (version 3).
  [[nodiscard]] CameraPoint camera_for_focus(double zoom_counts, double diopters) const;

  std::string name_;
  bool calibrated_ = true;
  MonotoneCurve focus_diopters_;            // counts -> 1/m; empty with per-zoom focus
  MonotoneCurve iris_stops_, t_stop_stops_; // counts -> 2*log2(N)
  std::vector<double> zoom_counts_;         // one entry for a prime
  std::vector<ZoomPoint> zoom_points_;
  MonotoneCurve log_focal_length_;  // zoom counts -> ln(mm); empty for a prime
  MonotoneCurve entrance_pupil_mm_; // zoom counts -> mm; empty for a prime
  std::optional<Distortion> distortion_;
  std::optional<Image> image_; // version 3
};

} // namespace camhead::lens_control
