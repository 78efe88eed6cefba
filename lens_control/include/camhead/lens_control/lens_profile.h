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
// (in diopters) per zoom calibration point, blended linearly between the two
// zoom points around the current zoom. The focus table itself is one table for
// all zoom positions (see README.md, "Limits").
//
// Thread safety: immutable after construction; any thread may call const
// members concurrently.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "camhead/lens_control/lens_state.h"
#include "camhead/lens_control/monotone_curve.h"

namespace camhead::lens_control {

// A profile file that cannot be used. what() reads "FILE: FIELD: REASON", where
// FIELD is a JSON path such as focus[3].distance_m (empty for whole-file
// problems such as unreadable files or JSON syntax errors).
class ProfileError : public std::runtime_error {
public:
  ProfileError(std::string file, std::string field, std::string reason);
  [[nodiscard]] const std::string &file() const { return file_; }
  [[nodiscard]] const std::string &field() const { return field_; }
  [[nodiscard]] const std::string &reason() const { return reason_; }

private:
  std::string file_, field_, reason_;
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

  // Single lookups, for tests and calibration tools.
  [[nodiscard]] Lookup focus_distance_m(double focus_counts) const;
  [[nodiscard]] Lookup f_number(double iris_counts) const;
  [[nodiscard]] std::optional<Lookup> t_stop(double iris_counts) const;
  [[nodiscard]] Lookup focal_length_mm(double zoom_counts) const;
  [[nodiscard]] Lookup projection_focal_length_mm(double zoom_counts, double focus_counts) const;
  [[nodiscard]] Lookup entrance_pupil_offset_mm(double zoom_counts) const;
  [[nodiscard]] const std::optional<Distortion> &distortion() const { return distortion_; }

  // The full lens state for aligned counts. An axis without a reading takes
  // the lens's rest value, not fresh: focus at the far end of the table, iris
  // wide open, zoom at its first calibration point.
  [[nodiscard]] LensState evaluate(const LensCounts &counts) const;

private:
  friend class ProfileReader; // profile_reader.cpp fills the tables

  // One zoom calibration point (a prime has exactly one).
  struct ZoomPoint {
    double focal_length_mm = 0.0;
    double entrance_pupil_offset_mm = 0.0;
    // Projection focal length over focus diopters; empty = no breathing data.
    MonotoneCurve breathing;
    std::optional<double> projection_focal_length_mm; // when given as one value
    bool has_pupil = false, has_projection = false;   // as given in the file
  };

  [[nodiscard]] double rest_counts_focus() const;
  [[nodiscard]] double rest_counts_iris() const;
  [[nodiscard]] double projection_at_point(const ZoomPoint &z, double diopters) const;

  std::string name_;
  bool calibrated_ = true;
  MonotoneCurve focus_diopters_;            // counts -> 1/m
  MonotoneCurve iris_stops_, t_stop_stops_; // counts -> 2*log2(N)
  std::vector<double> zoom_counts_;         // one entry for a prime
  std::vector<ZoomPoint> zoom_points_;
  MonotoneCurve log_focal_length_;  // zoom counts -> ln(mm); empty for a prime
  MonotoneCurve entrance_pupil_mm_; // zoom counts -> mm; empty for a prime
  std::optional<Distortion> distortion_;
};

} // namespace camhead::lens_control
