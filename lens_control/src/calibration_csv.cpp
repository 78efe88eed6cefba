// The measurements CSV reader of camhead calibrate. Strict, like the profile
// reader: a measurement file is typed by hand or by a script on set, and a
// value in the wrong column (an f-number in distance_m) must stop the run
// with the line and column named, not become a wrong calibration point.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>

#include "camhead/lens_control/calibration.h"

namespace camhead::lens_control {

namespace {

constexpr std::array<std::string_view, 7> kColumns = {
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

std::string_view trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!s.empty() && space(s.front()))
    s.remove_prefix(1);
  while (!s.empty() && space(s.back()))
    s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos)
      return cells;
    start = comma + 1;
  }
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char &c : out)
    c = char(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return out;
}

class CsvReader {
public:
  explicit CsvReader(std::string source) : source_(std::move(source)) {}

  MeasurementSet read(std::string_view text) {
    MeasurementSet out{source_, {}};
    std::size_t pos = 0;
    while (pos <= text.size()) {
      const std::size_t nl = std::min(text.find('\n', pos), text.size());
      std::string_view line = text.substr(pos, nl - pos);
      pos = nl + 1;
      ++line_;
      // '#' starts a comment anywhere: no value of this format contains one.
      line = trim(line.substr(0, line.find('#')));
      if (line.empty())
        continue;
      if (columns_.empty())
        header(split(line));
      else
        out.rows.push_back(row(split(line)));
    }
    if (columns_.empty())
      throw CalibrationError(source_, 0, "",
                             "no header row (expected e.g. axis,counts,distance_m,"
                             "f_number,t_stop,focal_length_mm)");
    check_t_stops(out.rows);
    check_zoom_counts(out.rows);
    return out;
  }

private:
  [[noreturn]] void fail(std::string_view column, const std::string &reason) const {
    throw CalibrationError(source_, line_, std::string(column), reason);
  }

  void header(const std::vector<std::string_view> &cells) {
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const std::string_view name = cells[i];
      if (name.empty())
        fail(std::to_string(i + 1), "empty column name in the header");
      if (std::find(kColumns.begin(), kColumns.end(), name) == kColumns.end())
        fail(name, "unknown column (known: axis, counts, distance_m, f_number, t_stop, "
                   "focal_length_mm, zoom_counts)");
      if (index_.count(std::string(name)))
        fail(name, "appears twice in the header");
      index_[std::string(name)] = i;
    }
    columns_.assign(cells.begin(), cells.end());
    for (const std::string_view required : {"axis", "counts"})
      if (!index_.count(std::string(required)))
        fail(required, "missing from the header");
  }

  // The cell of `column` in this row; empty when the header lacks the column.
  std::string_view cell(const std::vector<std::string_view> &cells, std::string_view column) const {
    const auto it = index_.find(std::string(column));
    return it == index_.end() ? std::string_view{} : cells[it->second];
  }

  Measurement row(const std::vector<std::string_view> &cells) const {
    if (cells.size() != columns_.size())
      fail("", "expected " + std::to_string(columns_.size()) + " fields as in the header, found " +
                   std::to_string(cells.size()));
    Measurement m;
    m.line = line_;
    const std::string_view axis = cell(cells, "axis");
    if (axis == "focus")
      m.axis = CalibrationAxis::focus;
    else if (axis == "iris")
      m.axis = CalibrationAxis::iris;
    else if (axis == "zoom")
      m.axis = CalibrationAxis::zoom;
    else
      fail("axis", "must be focus, iris or zoom, not \"" + std::string(axis) + "\"");
    m.counts = counts(cell(cells, "counts"));
    // The zoom position a focus mark was measured at: per-zoom focus tables.
    if (const std::string_view z = cell(cells, "zoom_counts"); !z.empty()) {
      if (m.axis != CalibrationAxis::focus)
        fail("zoom_counts", "not used by " + std::string(axis) +
                                " rows (only focus rows give the zoom they were measured at)");
      m.zoom_counts = counts(z, "zoom_counts");
    }

    // Only this axis's value columns may be filled: anything else is a value
    // typed into the wrong column or a row labelled with the wrong axis.
    const std::string_view needed = value_column(m.axis);
    for (const std::string_view c : {"distance_m", "f_number", "t_stop", "focal_length_mm"}) {
      const bool mine = c == needed || (m.axis == CalibrationAxis::iris && c == "t_stop");
      if (!mine && !cell(cells, c).empty())
        fail(c, "not used by " + std::string(axis) + " rows (leave it empty)");
    }
    const std::string_view v = cell(cells, needed);
    if (v.empty())
      fail(needed, index_.count(std::string(needed))
                       ? "missing (a " + std::string(axis) + " row needs a value here)"
                       : "missing from the header (" + std::string(axis) + " rows need it)");
    switch (m.axis) {
    case CalibrationAxis::focus:
      m.value = distance(v);
      break;
    case CalibrationAxis::iris:
      m.value = number(v, "f_number", 0.5, 128.0, false);
      if (const std::string_view t = cell(cells, "t_stop"); !t.empty()) {
        m.t_stop = number(t, "t_stop", 0.5, 256.0, false);
        if (*m.t_stop < m.value)
          fail("t_stop", "must be >= f_number: a T-stop includes transmission losses");
      }
      break;
    case CalibrationAxis::zoom:
      m.value = number(v, "focal_length_mm", 0.0, 1e4, true);
      break;
    }
    return m;
  }

  std::int32_t counts(std::string_view s, std::string_view column = "counts") const {
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc{} || end != s.data() + s.size())
      fail(column, "not an integer");
    if (v < std::numeric_limits<std::int32_t>::min() ||
        v > std::numeric_limits<std::int32_t>::max())
      fail(column, "outside the 32-bit encoder range");
    return std::int32_t(v);
  }

  double number(std::string_view s, std::string_view column, double lo, double hi,
                bool lo_open) const {
    double v = 0.0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc{} || end != s.data() + s.size())
      fail(column, "not a number");
    if (!std::isfinite(v))
      fail(column, "not a finite number");
    if ((lo_open ? !(v > lo) : !(v >= lo)) || v > hi) {
      std::ostringstream r;
      r << "must be " << (lo_open ? "> " : ">= ") << lo << " and <= " << hi;
      fail(column, r.str());
    }
    return v;
  }

  double distance(std::string_view s) const {
    const std::string l = lower(s);
    if (l == "inf" || l == "infinity")
      return std::numeric_limits<double>::infinity();
    return number(s, "distance_m", 0.0, 1e5, true);
  }

  // The profile format wants T-stops on every iris point or on none.
  void check_t_stops(const std::vector<Measurement> &rows) const {
    const Measurement *first = nullptr;
    for (const Measurement &m : rows) {
      if (m.axis != CalibrationAxis::iris)
        continue;
      if (!first)
        first = &m;
      else if (m.t_stop.has_value() != first->t_stop.has_value())
        throw CalibrationError(source_, m.line, "t_stop",
                               "give t_stop on every iris row or on none (line " +
                                   std::to_string(first->line) +
                                   (first->t_stop ? " has one)" : " has none)"));
    }
  }

  // Per-zoom focus tables need the zoom of every focus mark: on every focus
  // row or on none.
  void check_zoom_counts(const std::vector<Measurement> &rows) const {
    const Measurement *first = nullptr;
    for (const Measurement &m : rows) {
      if (m.axis != CalibrationAxis::focus)
        continue;
      if (!first)
        first = &m;
      else if (m.zoom_counts.has_value() != first->zoom_counts.has_value())
        throw CalibrationError(source_, m.line, "zoom_counts",
                               "give zoom_counts on every focus row or on none (line " +
                                   std::to_string(first->line) +
                                   (first->zoom_counts ? " has one)" : " has none)"));
    }
  }

  std::string source_;
  int line_ = 0;
  std::vector<std::string_view> columns_;
  std::map<std::string, std::size_t> index_;
};

} // namespace

CalibrationError::CalibrationError(std::string file, int line, std::string column,
                                   std::string reason)
    : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : "") + ": " +
                         (column.empty() ? ""
                          : line > 0     ? "column " + column + ": "
                                         : column + ": ") +
                         reason),
      file_(std::move(file)), line_(line), column_(std::move(column)), reason_(std::move(reason)) {}

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
  return CsvReader(source).read(csv);
}

MeasurementSet read_measurements(const std::filesystem::path &path) {
  std::ifstream in(path, std::ios::binary);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (!in.is_open() || in.bad())
    throw CalibrationError(path.string(), 0, "", "cannot read the file");
  return parse_measurements(text, path.string());
}

} // namespace camhead::lens_control
