// The measurements CSV reader of camhead calibrate. Strict, like the profile
// reader: a measurement file is typed by hand or by a script on set, and a
// value in the wrong column (an f-number in distance_m) must stop the run
// with the line and column named, not become a wrong calibration point. The
// lines, header and numbers are base's strict CSV reader (config_csv.h).
#include <cstdint>
#include <limits>

#include "camhead/base/config_csv.h"
#include "camhead/lens_control/calibration.h"

namespace camhead::lens_control {

namespace {

using base::CsvReader;
using base::CsvRow;
using base::Range;

const std::vector<std::string_view> kColumns = {
    "axis", "counts", "distance_m", "f_number", "t_stop", "focal_length_mm", "zoom_counts"};

// The value column each axis needs; t_stop is iris's optional second one.
std::string_view value_column(CalibrationAxis a) {
  switch (a) {
  case CalibrationAxis::focus:
    return "distance_m";
  case CalibrationAxis::iris:
    return "f_number";
  case CalibrationAxis::zoom:
    return "focal_length_mm";
  }
  return "";
}

std::int32_t counts(const CsvReader &csv, std::string_view cell, std::string_view column) {
  return std::int32_t(csv.integer(cell, column, std::numeric_limits<std::int32_t>::min(),
                                  std::numeric_limits<std::int32_t>::max()));
}

Measurement row(const CsvReader &csv, const CsvRow &cells) {
  Measurement m;
  m.line = csv.line();
  const std::string_view axis = csv.cell(cells, "axis");
  if (axis == "focus")
    m.axis = CalibrationAxis::focus;
  else if (axis == "iris")
    m.axis = CalibrationAxis::iris;
  else if (axis == "zoom")
    m.axis = CalibrationAxis::zoom;
  else
    csv.fail("axis", "must be focus, iris or zoom, not \"" + std::string(axis) + "\"");
  m.counts = counts(csv, csv.cell(cells, "counts"), "counts");
  // The zoom position a focus mark was measured at: per-zoom focus tables.
  if (const std::string_view z = csv.cell(cells, "zoom_counts"); !z.empty()) {
    if (m.axis != CalibrationAxis::focus)
      csv.fail("zoom_counts", "not used by " + std::string(axis) +
                                  " rows (only focus rows give the zoom they were measured at)");
    m.zoom_counts = counts(csv, z, "zoom_counts");
  }

  // Only this axis's value columns may be filled: anything else is a value
  // typed into the wrong column or a row labelled with the wrong axis.
  const std::string_view needed = value_column(m.axis);
  for (const std::string_view c : {"distance_m", "f_number", "t_stop", "focal_length_mm"}) {
    const bool mine = c == needed || (m.axis == CalibrationAxis::iris && c == "t_stop");
    if (!mine && !csv.cell(cells, c).empty())
      csv.fail(c, "not used by " + std::string(axis) + " rows (leave it empty)");
  }
  const std::string_view v = csv.cell(cells, needed);
  if (v.empty())
    csv.fail(needed, csv.has_column(needed)
                         ? "missing (a " + std::string(axis) + " row needs a value here)"
                         : "missing from the header (" + std::string(axis) + " rows need it)");
  switch (m.axis) {
  case CalibrationAxis::focus:
    // Nothing focuses closer than a millimetre, and 1/d of a smaller
    // positive number (1e-310) would overflow the curve fitted through it.
    m.value = csv.number(v, "distance_m", Range::within(1e-3, 1e5), /*infinity_allowed=*/true);
    break;
  case CalibrationAxis::iris:
    m.value = csv.number(v, "f_number", Range::within(0.5, 128.0));
    if (const std::string_view t = csv.cell(cells, "t_stop"); !t.empty()) {
      m.t_stop = csv.number(t, "t_stop", Range::within(0.5, 256.0));
      if (*m.t_stop < m.value)
        csv.fail("t_stop", "must be >= f_number: a T-stop includes transmission losses");
    }
    break;
  case CalibrationAxis::zoom:
    m.value = csv.number(v, "focal_length_mm", Range::above(0.0, 1e4));
    break;
  }
  return m;
}

// The profile format wants T-stops on every iris point or on none.
void check_t_stops(const MeasurementSet &set) {
  const Measurement *first = nullptr;
  for (const Measurement &m : set.rows) {
    if (m.axis != CalibrationAxis::iris)
      continue;
    if (!first)
      first = &m;
    else if (m.t_stop.has_value() != first->t_stop.has_value())
      throw CalibrationError(set.source, m.line, "t_stop",
                             "give t_stop on every iris row or on none (line " +
                                 std::to_string(first->line) +
                                 (first->t_stop ? " has one)" : " has none)"));
  }
}

// Per-zoom focus tables need the zoom of every focus mark: on every focus
// row or on none.
void check_zoom_counts(const MeasurementSet &set) {
  const Measurement *first = nullptr;
  for (const Measurement &m : set.rows) {
    if (m.axis != CalibrationAxis::focus)
      continue;
    if (!first)
      first = &m;
    else if (m.zoom_counts.has_value() != first->zoom_counts.has_value())
      throw CalibrationError(set.source, m.line, "zoom_counts",
                             "give zoom_counts on every focus row or on none (line " +
                                 std::to_string(first->line) +
                                 (first->zoom_counts ? " has one)" : " has none)"));
  }
}

} // namespace

const char *axis_name(CalibrationAxis axis) {
  switch (axis) {
  case CalibrationAxis::focus:
    return "focus";
  case CalibrationAxis::iris:
    return "iris";
  case CalibrationAxis::zoom:
    return "zoom";
  }
  return "?";
}

MeasurementSet parse_measurements(std::string_view csv, const std::string &source) {
  MeasurementSet out{source, {}};
  try {
    // '#' starts a comment anywhere: no value of this format contains one.
    CsvReader reader(source, csv, CsvReader::Comments::anywhere);
    reader.read_header(kColumns, "axis,counts,distance_m,f_number,t_stop,focal_length_mm");
    reader.require_column("axis");
    reader.require_column("counts");
    while (const std::optional<CsvRow> cells = reader.next_row())
      out.rows.push_back(row(reader, *cells));
  } catch (const base::ConfigError &e) {
    throw CalibrationError(e);
  }
  check_t_stops(out);
  check_zoom_counts(out);
  return out;
}

MeasurementSet read_measurements(const std::filesystem::path &path) {
  std::string text;
  try {
    text = base::read_config_file(path);
  } catch (const base::ConfigError &e) {
    throw CalibrationError(e);
  }
  return parse_measurements(text, path.string());
}

} // namespace camhead::lens_control
