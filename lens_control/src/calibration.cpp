// The fit of camhead calibrate: averaging repeats, the monotone fit
// (pool-adjacent-violators) and the profile JSON writer. Why these spaces and
// why an isotonic fit: see calibration.h.
#include "camhead/lens_control/calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

namespace camhead::lens_control {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Into and out of the space the profile interpolates each quantity in
// (profile_reader.cpp and lens_profile.cpp use the same conversions). A
// T-stop converts like an f-number.
double to_linear(CalibrationAxis a, double v) {
  switch (a) {
  case CalibrationAxis::focus:
    return std::isinf(v) ? 0.0 : 1.0 / v;
  case CalibrationAxis::iris:
    return 2.0 * std::log2(v);
  case CalibrationAxis::zoom:
    return std::log(v);
  }
  return v;
}

double from_linear(CalibrationAxis a, double y) {
  switch (a) {
  case CalibrationAxis::focus:
    return y > 0.0 ? 1.0 / y : kInf;
  case CalibrationAxis::iris:
    return std::exp2(0.5 * y);
  case CalibrationAxis::zoom:
    return std::exp(y);
  }
  return y;
}

// Adjacent measured counts fitted as one point. Kept as sums so that pooling
// two blocks is adding them, and the pooled mean is the mean of all the
// measurements behind it (each measurement weighs the same).
struct Block {
  double counts_sum = 0.0;
  double weight = 0.0;     // number of measurements
  std::vector<double> sum; // per channel (value, then t_stop), linearised
  // Per channel, the natural value when every measurement in the block has
  // that same value: written as measured, so that exact data reproduce
  // themselves without a round trip through log and exp.
  std::vector<std::optional<double>> same;
  std::int32_t first = 0, last = 0;
  std::size_t distinct = 0;

  [[nodiscard]] double mean(std::size_t c) const { return sum[c] / weight; }
  // What the profile will say for channel c.
  [[nodiscard]] double written(CalibrationAxis axis, std::size_t c) const {
    return same[c] ? *same[c] : from_linear(axis, mean(c));
  }

  void absorb(const Block &b) {
    counts_sum += b.counts_sum;
    weight += b.weight;
    for (std::size_t c = 0; c < sum.size(); ++c) {
      sum[c] += b.sum[c];
      if (same[c] != b.same[c])
        same[c].reset();
    }
    last = b.last;
    distinct += b.distinct;
  }
};

// Strictly monotone in direction dir[c] in every channel between a and b,
// both in the linear space and as written: repeats that all say 20 m average
// to 1 ulp off 1/20 D, which orders them against a lone 20 m beside them,
// yet both are written as 20 and the profile reader refuses the tie
// (tests/fuzz/calibration_fuzz). Distance falls as diopters rise.
bool in_order(const Block &a, const Block &b, const std::vector<double> &dir,
              CalibrationAxis axis) {
  const double written_dir = axis == CalibrationAxis::focus ? -1.0 : 1.0;
  for (std::size_t c = 0; c < dir.size(); ++c)
    if (!((b.mean(c) - a.mean(c)) * dir[c] > 0.0) ||
        !((b.written(axis, c) - a.written(axis, c)) * dir[c] * written_dir > 0.0))
      return false;
  return true;
}

// Pool-adjacent-violators with a stack: after each push, merge the top two
// blocks while they are out of order (ties included, so the result is
// strictly monotone). Every adjacent pair left on the stack is in order, and
// a merged mean lies between its parts, so the pairs below stay in order.
// With one channel this is the least-squares isotonic regression; with two
// (f-number and T-stop) a pair out of order in either is merged in both.
// The written values can break that invariant by rounding, so the passes
// repeat until one merges nothing.
std::vector<Block> pool_adjacent_violators(std::vector<Block> blocks,
                                           const std::vector<double> &dir, CalibrationAxis axis) {
  for (std::size_t before = 0; before != blocks.size();) {
    before = blocks.size();
    std::vector<Block> out;
    for (const Block &b : blocks) {
      out.push_back(b);
      while (out.size() >= 2 && !in_order(out[out.size() - 2], out.back(), dir, axis)) {
        const Block top = out.back();
        out.pop_back();
        out.back().absorb(top);
      }
    }
    blocks = std::move(out);
  }
  return blocks;
}

// +1 or -1: the sign of the least-squares slope of channel c over counts, over
// all measurements (a block's repeats share its counts, hence the weights).
double trend(const std::vector<Block> &blocks, std::size_t c) {
  double w = 0.0, x = 0.0, y = 0.0;
  for (const Block &b : blocks) {
    w += b.weight;
    x += b.counts_sum;
    y += b.sum[c];
  }
  x /= w;
  y /= w;
  double sxy = 0.0;
  for (const Block &b : blocks)
    sxy += (b.counts_sum / b.weight - x) * (b.sum[c] - b.weight * y);
  return sxy >= 0.0 ? 1.0 : -1.0;
}

std::vector<const Measurement *> rows_of(const MeasurementSet &m, CalibrationAxis axis) {
  std::vector<const Measurement *> rows;
  for (const Measurement &r : m.rows)
    if (r.axis == axis)
      rows.push_back(&r);
  return rows;
}

// One table fitted from `rows` (all of one axis); `name` names it in errors:
// the axis, or e.g. "focus at zoom counts 900" for a per-zoom focus table.
AxisFit fit_axis(const std::string &source, const std::string &name, CalibrationAxis axis,
                 std::vector<const Measurement *> rows, bool prime) {
  const auto fail = [&](const std::string &reason) -> void {
    throw CalibrationError(source, 0, name, reason);
  };
  if (rows.empty())
    fail("no measurements (a profile needs focus, iris and zoom rows; for a prime, one zoom "
         "row with its focal length and --prime)");
  std::stable_sort(rows.begin(), rows.end(), [](const Measurement *a, const Measurement *b) {
    return a->counts < b->counts;
  });

  // Repeats at equal counts: one block each, averaged in the linear space.
  const std::size_t channels = rows.front()->t_stop ? 2 : 1;
  std::vector<Block> blocks;
  for (const Measurement *r : rows) {
    const double values[2] = {r->value, r->t_stop.value_or(0.0)};
    if (blocks.empty() || blocks.back().last != r->counts) {
      blocks.push_back(
          Block{0.0, 0.0, std::vector<double>(channels, 0.0), {}, r->counts, r->counts, 1});
      blocks.back().same.assign(values, values + channels);
    }
    Block &b = blocks.back();
    b.counts_sum += r->counts;
    b.weight += 1.0;
    for (std::size_t c = 0; c < channels; ++c) {
      b.sum[c] += to_linear(axis, values[c]);
      if (b.same[c] != values[c])
        b.same[c].reset();
    }
  }

  AxisFit fit{axis, rows.size(), blocks.size(), {}};
  const bool one_point = prime && axis == CalibrationAxis::zoom;
  if (one_point && blocks.size() != 1)
    fail("--prime needs every zoom row at the same counts (a prime has one focal length); "
         "found " +
         std::to_string(blocks.size()) + " distinct counts");
  if (!one_point && blocks.size() < 2)
    fail(std::to_string(rows.size()) + " measurement(s), all at counts " +
         std::to_string(blocks.front().first) + ": a table needs 2 or more distinct counts" +
         (axis == CalibrationAxis::zoom ? " (for a prime lens, pass --prime)" : ""));
  if (!one_point) {
    std::vector<double> dir;
    for (std::size_t c = 0; c < channels; ++c)
      dir.push_back(trend(blocks, c));
    blocks = pool_adjacent_violators(std::move(blocks), dir, axis);
    if (blocks.size() < 2)
      fail("the monotone fit pools all " + std::to_string(rows.size()) +
           " measurements into one point: the values show no trend over counts (fewer than 2 "
           "distinct points remain)");
  }

  for (const Block &b : blocks) {
    FittedPoint p;
    p.counts = std::int32_t(std::llround(b.counts_sum / b.weight));
    p.value = b.written(axis, 0);
    if (channels == 2)
      p.t_stop = b.written(axis, 1);
    p.first_counts = b.first;
    p.last_counts = b.last;
    p.distinct_counts = b.distinct;
    p.measurements = std::size_t(b.weight);
    // Averaging infinity with a very far mark can land beyond the largest
    // finite distance a profile accepts; say so here rather than as a
    // failed round trip.
    if (axis == CalibrationAxis::focus && std::isfinite(p.value) && p.value > 1e5) {
      std::ostringstream r;
      r << "the point at counts " << p.counts << " averages to " << p.value
        << " m, beyond the 1e5 m a profile allows (measure that mark as inf or nearer)";
      fail(r.str());
    }
    fit.points.push_back(p);
  }
  return fit;
}

AxisFit fit_axis(const MeasurementSet &m, CalibrationAxis axis, bool prime) {
  return fit_axis(m.source, axis_name(axis), axis, rows_of(m, axis), prime);
}

// Per-zoom focus tables: the focus rows at each fitted zoom point, fitted as
// that point's table. A zoom point the monotone fit pooled from several zoom
// marks takes the focus rows of all of them.
std::vector<AxisFit> fit_zoom_focus(const MeasurementSet &m, const AxisFit &zoom) {
  std::vector<std::vector<const Measurement *>> groups(zoom.points.size());
  const std::vector<const Measurement *> zoom_rows = rows_of(m, CalibrationAxis::zoom);
  for (const Measurement *r : rows_of(m, CalibrationAxis::focus)) {
    const std::int32_t z = *r->zoom_counts;
    if (std::none_of(zoom_rows.begin(), zoom_rows.end(),
                     [&](const Measurement *q) { return q->counts == z; }))
      throw CalibrationError(m.source, r->line, "zoom_counts",
                             "no zoom row at counts " + std::to_string(z) +
                                 " (a focus mark must be measured at a zoom calibration mark, "
                                 "whose focal length a zoom row gives)");
    for (std::size_t i = 0; i < zoom.points.size(); ++i)
      if (z >= zoom.points[i].first_counts && z <= zoom.points[i].last_counts)
        groups[i].push_back(r);
  }
  std::vector<AxisFit> tables;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    const std::string name = "focus at zoom counts " + std::to_string(zoom.points[i].counts);
    if (groups[i].empty())
      throw CalibrationError(m.source, 0, name,
                             "no focus measurements (with a zoom_counts column, every zoom "
                             "point needs its own focus marks)");
    tables.push_back(fit_axis(m.source, name, CalibrationAxis::focus, groups[i], false));
  }
  // The profile reader's rule: tables that run opposite ways would blend into
  // a focus that runs backwards between their zoom points.
  const auto rising = [](const AxisFit &t) {
    return to_linear(CalibrationAxis::focus, t.points.back().value) >
           to_linear(CalibrationAxis::focus, t.points.front().value);
  };
  for (std::size_t i = 1; i < tables.size(); ++i)
    if (rising(tables[i]) != rising(tables[0]))
      throw CalibrationError(
          m.source, 0, "focus at zoom counts " + std::to_string(zoom.points[i].counts),
          std::string("the fitted distances ") + (rising(tables[i]) ? "fall" : "rise") +
              " as counts rise, the other way from the table at zoom counts " +
              std::to_string(zoom.points[0].counts) +
              ": every zoom point's focus table must run the same way");
  return tables;
}

std::string num(double v) {
  return nlohmann::json(v).dump();
}

std::string table(const AxisFit &fit, const char *key, const std::string &indent = "    ") {
  std::string s = "[\n";
  for (std::size_t i = 0; i < fit.points.size(); ++i) {
    const FittedPoint &p = fit.points[i];
    s += indent + "{\"counts\": " + std::to_string(p.counts) + ", \"" + key +
         "\": " + (std::isinf(p.value) ? std::string("\"infinity\"") : num(p.value));
    if (p.t_stop)
      s += ", \"t_stop\": " + num(*p.t_stop);
    s += i + 1 < fit.points.size() ? "},\n" : "}\n";
  }
  return s + indent.substr(2) + "]";
}

// The zoom table with a focus table on every point (format version 2).
std::string zoom_table_with_focus(const Calibration &fit) {
  std::string s = "[\n";
  for (std::size_t i = 0; i < fit.zoom.points.size(); ++i) {
    const FittedPoint &p = fit.zoom.points[i];
    s += "    {\"counts\": " + std::to_string(p.counts) + ", \"focal_length_mm\": " + num(p.value) +
         ", \"focus\": " + table(fit.zoom_focus[i], "distance_m", "      ");
    s += i + 1 < fit.zoom.points.size() ? "},\n" : "}\n";
  }
  return s + "  ]";
}

} // namespace

Calibration fit_calibration(const MeasurementSet &measurements, const CalibrationOptions &options) {
  if (options.name.empty())
    throw CalibrationError(measurements.source, 0, "name", "the profile needs a non-empty name");
  Calibration c;
  c.source = measurements.source;
  c.prime = options.prime;
  // Per-zoom focus when the focus rows give the zoom they were measured at
  // (on all of them or none: the CSV reader checks).
  const std::vector<const Measurement *> focus = rows_of(measurements, CalibrationAxis::focus);
  const bool per_zoom = !focus.empty() && focus.front()->zoom_counts;
  if (per_zoom && options.prime)
    throw CalibrationError(measurements.source, 0, "focus",
                           "the zoom_counts column gives per-zoom focus tables, which need a "
                           "zoom lens: leave the column out for a prime (--prime)");
  if (!per_zoom)
    c.focus = fit_axis(measurements, CalibrationAxis::focus, options.prime);
  c.iris = fit_axis(measurements, CalibrationAxis::iris, options.prime);
  c.zoom = fit_axis(measurements, CalibrationAxis::zoom, options.prime);
  if (per_zoom) {
    c.zoom_focus = fit_zoom_focus(measurements, c.zoom);
    c.focus = AxisFit{CalibrationAxis::focus, focus.size(), 0, {}};
    for (const AxisFit &t : c.zoom_focus)
      c.focus.distinct_counts += t.distinct_counts;
  }
  return c;
}

std::string profile_json(const Calibration &fit, const CalibrationOptions &options) {
  const std::size_t n = fit.focus.measurements + fit.iris.measurements + fit.zoom.measurements;
  const std::string description = !options.description.empty()
                                      ? options.description
                                      : "Fitted by camhead calibrate from " +
                                            std::filesystem::path(fit.source).filename().string() +
                                            " (" + std::to_string(n) + " measurements).";
  std::string s = "{\n";
  s += "  \"format\": \"camhead-lens-profile\",\n";
  const bool per_zoom = !fit.zoom_focus.empty();
  // Version 2 only when needed: a version 1 reader then still reads the rest.
  s += per_zoom ? "  \"version\": 2,\n" : "  \"version\": 1,\n";
  s += "  \"name\": " + nlohmann::json(options.name).dump() + ",\n";
  s += "  \"description\": " + nlohmann::json(description).dump() + ",\n";
  if (!per_zoom)
    s += "  \"focus\": " + table(fit.focus, "distance_m") + ",\n";
  s += "  \"iris\": " + table(fit.iris, "f_number") + ",\n";
  if (fit.prime)
    s += "  \"prime\": {\"focal_length_mm\": " + num(fit.zoom.points.front().value) + "}\n";
  else if (per_zoom)
    s += "  \"zoom\": " + zoom_table_with_focus(fit) + "\n";
  else
    s += "  \"zoom\": " + table(fit.zoom, "focal_length_mm") + "\n";
  return s + "}\n";
}

} // namespace camhead::lens_control
