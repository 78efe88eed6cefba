// Residuals of camhead calibrate and its report. The residuals go through
// LensProfile's own lookups, not through the fit's arithmetic, so they
// measure the profile that will actually be used: PCHIP between the written
// points, clamping outside them, and every conversion on the way.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <map>

#include "camhead/lens_control/calibration.h"

namespace camhead::lens_control {

namespace {

double diopters(double distance_m) {
  return std::isinf(distance_m) ? 0.0 : 1.0 / distance_m;
}

double stops(double n) {
  return 2.0 * std::log2(n);
}

// Running RMS and largest absolute residual of one quantity.
struct Accumulator {
  explicit Accumulator(std::string q) : quantity(std::move(q)) {}

  std::string quantity;
  std::size_t n = 0;
  double squares = 0.0;
  Residuals out;

  void add(double residual, std::int32_t counts) {
    ++n;
    squares += residual * residual;
    if (n == 1 || std::abs(residual) > out.max_abs) {
      out.max_abs = std::abs(residual);
      out.max_at_counts = counts;
    }
  }
  void emit(std::vector<Residuals> &into) {
    if (n == 0)
      return;
    out.quantity = quantity;
    out.count = n;
    out.rms = std::sqrt(squares / double(n));
    into.push_back(out);
  }
};

std::string format(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char *fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return buf;
}

std::string show_value(CalibrationAxis axis, const FittedPoint &p) {
  switch (axis) {
  case CalibrationAxis::focus:
    return std::isinf(p.value) ? "infinity" : format("%.4g m", p.value);
  case CalibrationAxis::iris:
    return format("f/%.3g", p.value) + (p.t_stop ? format(", T%.3g", *p.t_stop) : "");
  case CalibrationAxis::zoom:
    return format("%.4g mm", p.value);
  }
  return "";
}

} // namespace

std::vector<Residuals> compute_residuals(const MeasurementSet &measurements,
                                         const LensProfile &profile) {
  double closest = std::numeric_limits<double>::infinity();
  for (const Measurement &m : measurements.rows)
    if (m.axis == CalibrationAxis::focus)
      closest = std::min(closest, m.value);
  const double near_limit = 2.0 * closest;

  Accumulator focus_d("focus, diopters");
  Accumulator focus_m(format("focus, m (d <= %.3g m)", near_limit));
  Accumulator f_number("iris f-number, stops"), t_stop("iris T-stop, stops");
  Accumulator zoom("zoom focal length, mm");
  // Per measured zoom counts, for per-zoom focus: which zoom a focus error
  // comes from.
  std::map<std::int32_t, Accumulator> focus_at_zoom;
  for (const Measurement &m : measurements.rows) {
    const double c = m.counts;
    switch (m.axis) {
    case CalibrationAxis::focus: {
      // At the zoom the mark was measured at, when the file says.
      const double d = m.zoom_counts ? profile.focus_distance_m(*m.zoom_counts, c).value
                                     : profile.focus_distance_m(c).value;
      const double r = diopters(m.value) - diopters(d);
      focus_d.add(r, m.counts);
      if (m.value <= near_limit)
        focus_m.add(m.value - d, m.counts);
      if (m.zoom_counts)
        focus_at_zoom
            .try_emplace(*m.zoom_counts, format("focus @ zoom %d, diopters", int(*m.zoom_counts)))
            .first->second.add(r, m.counts);
      break;
    }
    case CalibrationAxis::iris:
      f_number.add(stops(m.value) - stops(profile.f_number(c).value), m.counts);
      if (const auto t = profile.t_stop(c); t && m.t_stop)
        t_stop.add(stops(*m.t_stop) - stops(t->value), m.counts);
      break;
    case CalibrationAxis::zoom:
      zoom.add(m.value - profile.focal_length_mm(c).value, m.counts);
      break;
    }
  }
  std::vector<Residuals> out;
  focus_d.emit(out);
  focus_m.emit(out);
  for (auto &[z, a] : focus_at_zoom)
    a.emit(out);
  for (Accumulator *a : {&f_number, &t_stop, &zoom})
    a->emit(out);
  return out;
}

std::string format_report(const Calibration &fit, const std::vector<Residuals> &residuals) {
  std::string s = "camhead calibrate: " + fit.source + "\n\n";
  s += format("%-6s %12s %16s %15s\n", "axis", "measurements", "distinct counts", "points written");
  std::size_t focus_points = fit.focus.points.size();
  for (const AxisFit &t : fit.zoom_focus)
    focus_points += t.points.size();
  for (const AxisFit *a : {&fit.focus, &fit.iris, &fit.zoom}) {
    const bool focus = a->axis == CalibrationAxis::focus;
    s += format("%-6s %12zu %16zu %15zu%s\n", axis_name(a->axis), a->measurements,
                a->distinct_counts, focus ? focus_points : a->points.size(),
                a->axis == CalibrationAxis::zoom && fit.prime ? " (prime)"
                : focus && !fit.zoom_focus.empty()
                    ? format(" (%zu tables, one per zoom point)", fit.zoom_focus.size()).c_str()
                    : "");
    // Per-zoom focus: one row per table, under the focus total.
    if (focus)
      for (std::size_t i = 0; i < fit.zoom_focus.size(); ++i) {
        // Right-aligned under "measurements", as the axis rows are.
        const std::string label = format("  @ zoom %d", int(fit.zoom.points[i].counts));
        s += format("%s%*zu %16zu %15zu\n", label.c_str(), std::max(1, 19 - int(label.size())),
                    fit.zoom_focus[i].measurements, fit.zoom_focus[i].distinct_counts,
                    fit.zoom_focus[i].points.size());
      }
  }

  s += format("\n%-30s %5s %11s %11s %10s\n", "residual, measured - profile", "n", "rms", "max",
              "at counts");
  for (const Residuals &r : residuals)
    s += format("%-30s %5zu %11.3g %11.3g %10d\n", r.quantity.c_str(), r.count, r.rms, r.max_abs,
                int(r.max_at_counts));

  std::string pooled;
  const auto pooled_in = [&](const AxisFit &a, const std::string &name) {
    for (const FittedPoint &p : a.points)
      if (p.distinct_counts > 1)
        pooled += format("  %s: counts %d..%d (%zu counts, %zu measurements) -> counts %d, %s\n",
                         name.c_str(), int(p.first_counts), int(p.last_counts), p.distinct_counts,
                         p.measurements, int(p.counts), show_value(a.axis, p).c_str());
  };
  pooled_in(fit.focus, "focus");
  for (std::size_t i = 0; i < fit.zoom_focus.size(); ++i)
    pooled_in(fit.zoom_focus[i], format("focus @ zoom %d", int(fit.zoom.points[i].counts)));
  pooled_in(fit.iris, "iris");
  pooled_in(fit.zoom, "zoom");
  s += pooled.empty()
           ? "\npooled by the monotone fit: none (the averaged points were monotone)\n"
           : "\npooled by the monotone fit (not monotone within measurement noise):\n" + pooled;
  return s;
}

} // namespace camhead::lens_control
