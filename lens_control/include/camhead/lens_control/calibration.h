// Building a lens profile from measured (counts, value) pairs: the CSV reader,
// the fit, the profile JSON writer and the residual report behind
// `camhead calibrate` (CSV format in lens_control/README.md).
//
// The fit works in the same linearising spaces the profile interpolates in
// (diopters, stops, log f), so that averaging repeats and pooling noisy points
// mean the same thing as the interpolation between the written points: two
// focus readings of 1 m and infinity at one mark average to 0.5 D (2 m), not
// to an infinite distance.
//
// Why an isotonic fit: a profile must be strictly monotone (profile_reader
// rejects anything else, so that the rendered focus never runs backwards
// while the ring turns one way), but measurements near flat parts of a scale
// (the far end of focus, the long end of a zoom) can cross each other by
// measurement noise. Pool-adjacent-violators gives the least-squares monotone
// fit to them instead of refusing the data or silently dropping points.
//
// Thread safety: free functions on values; nothing shared.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "camhead/base/config_error.h"
#include "camhead/lens_control/lens_profile.h"

namespace camhead::lens_control {

// Measurements that cannot be turned into a profile. what() reads
// "FILE:LINE: COLUMN: REASON" for a problem on one CSV line ("header" or
// "row" as the column when the whole line is wrong), and "FILE: AXIS: REASON"
// for a problem of one axis as a whole (line() == 0), e.g. too few points
// (base/config_error.h).
class CalibrationError : public base::ConfigError {
public:
  using base::ConfigError::ConfigError;
  explicit CalibrationError(const base::ConfigError &e) : base::ConfigError(e) {}
  [[nodiscard]] const std::string &column() const { return field(); }
};

enum class CalibrationAxis { focus, iris, zoom };
[[nodiscard]] const char *axis_name(CalibrationAxis axis);

// One CSV row, validated: value is distance_m (+infinity allowed) for focus,
// f_number for iris, focal_length_mm for zoom.
struct Measurement {
  CalibrationAxis axis = CalibrationAxis::focus;
  std::int32_t counts = 0;
  double value = 0.0;
  std::optional<double> t_stop; // iris rows, when the file has T-stops
  // Focus rows, when the file has a zoom_counts column: the zoom encoder
  // counts the mark was measured at (per-zoom focus tables).
  std::optional<std::int32_t> zoom_counts;
  int line = 0; // 1-based line in the CSV, for messages
};

struct MeasurementSet {
  std::string source; // file name as given, for messages and the report
  std::vector<Measurement> rows;
};

// Throws CalibrationError naming `source`, the line and the column.
[[nodiscard]] MeasurementSet parse_measurements(std::string_view csv, const std::string &source);
[[nodiscard]] MeasurementSet read_measurements(const std::filesystem::path &path);

// One calibration point of the fitted profile, in natural units.
struct FittedPoint {
  std::int32_t counts = 0;
  double value = 0.0; // distance_m (+infinity), f_number or focal_length_mm
  std::optional<double> t_stop;
  // The measured counts behind this point: one value, or a range of
  // distinct_counts > 1 values pooled by the monotone fit.
  std::int32_t first_counts = 0, last_counts = 0;
  std::size_t distinct_counts = 0;
  std::size_t measurements = 0;
};

struct AxisFit {
  CalibrationAxis axis = CalibrationAxis::focus;
  std::size_t measurements = 0;
  std::size_t distinct_counts = 0;
  std::vector<FittedPoint> points;
};

struct CalibrationOptions {
  std::string name;        // required, the profile's "name"
  std::string description; // empty: one naming the measurements file
  bool prime = false;      // write zoom's single point as "prime"
};

struct Calibration {
  std::string source;
  // With per-zoom focus, `focus` only counts all focus measurements (no
  // points); the tables are in zoom_focus.
  AxisFit focus, iris, zoom;
  bool prime = false;
  // Per-zoom focus tables (profile format version 2), one per zoom.points
  // entry, when the focus rows give zoom_counts; empty otherwise.
  std::vector<AxisFit> zoom_focus;
};

// Averages repeats at equal counts in the linearising space, then pools
// adjacent points until every quantity is strictly monotone over counts, in
// the direction of its least-squares trend. Iris f-number and T-stop share
// their counts, so a point pooled for either is pooled for both. Throws
// CalibrationError when an axis has no measurements or keeps fewer than 2
// points (exactly 1 zoom point, at one counts value, with options.prime).
// When the focus rows give zoom_counts, each must be the counts of a zoom row,
// and the focus rows at each fitted zoom point (a point the monotone fit
// pooled from several zoom marks takes the focus rows of all of them) are
// fitted as that point's own table; every zoom point needs one, and all must
// run the same way (the profile reader's rule for per-zoom focus tables).
[[nodiscard]] Calibration fit_calibration(const MeasurementSet &measurements,
                                          const CalibrationOptions &options);

// Profile JSON of a fit: format version 1, or version 2 with a focus table on
// every zoom point when the fit has per-zoom focus. LensProfile::parse reads it.
[[nodiscard]] std::string profile_json(const Calibration &fit, const CalibrationOptions &options);

// Residuals of the measurements against a profile, measured minus profile,
// evaluated through the profile's own interpolation.
struct Residuals {
  std::string quantity; // e.g. "focus, diopters"
  std::size_t count = 0;
  double rms = 0.0;
  double max_abs = 0.0;
  std::int32_t max_at_counts = 0;
};

// Focus in diopters (all rows) and in metres (near end only: measured
// distances up to twice the closest one, where a metre is a meaningful unit;
// further out the same focus error grows as distance squared), then, when the
// focus rows give zoom_counts, focus in diopters per measured zoom counts
// (each row evaluated at its own zoom), iris f-number and T-stop in stops,
// zoom in mm.
[[nodiscard]] std::vector<Residuals> compute_residuals(const MeasurementSet &measurements,
                                                       const LensProfile &profile);

// The human-readable report: per axis the measurements, distinct counts and
// points written; the residual table; the points the monotone fit pooled.
[[nodiscard]] std::string format_report(const Calibration &fit,
                                        const std::vector<Residuals> &residuals);

} // namespace camhead::lens_control
