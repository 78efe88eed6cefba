// Table lookups of a loaded profile: the conversions between each quantity
// and the space it is interpolated in, zoom blending, and the fallback lens.
// Parsing and validation live in profile_reader.cpp.
#include "camhead/lens_control/lens_profile.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace camhead::lens_control {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double from_diopters(double d) {
  return d > 0.0 ? 1.0 / d : kInf;
}
double from_stops(double s) {
  return std::exp2(0.5 * s);
}

} // namespace

LensProfile LensProfile::uncalibrated() {
  // Constant tables spanning every possible count, so that the generic lookups
  // apply unchanged and nothing is ever reported as clamped: the single flag
  // that matters is calibrated == false.
  const std::vector<double> all{double(std::numeric_limits<std::int32_t>::min()),
                                double(std::numeric_limits<std::int32_t>::max())};
  LensProfile p;
  p.name_ = "uncalibrated: nominal 35 mm f/2.8 focused at infinity, encoders ignored";
  p.calibrated_ = false;
  p.focus_diopters_ = MonotoneCurve(all, {0.0, 0.0});
  const double stops = 2.0 * std::log2(2.8);
  p.iris_stops_ = MonotoneCurve(all, {stops, stops});
  p.zoom_counts_ = {0.0};
  p.zoom_points_ = {ZoomPoint{35.0, 0.0, {}, std::nullopt, false, false, {}}};
  return p;
}

LensProfile::ZoomSpan LensProfile::zoom_span(double zoom_counts) const {
  if (!is_zoom())
    return {};
  // The weight breathing has always been blended with: linear in zoom counts
  // between the two calibration points around the zoom. Exactly 0 at a point
  // and at or before the first, exactly 1 at or beyond the last, so that a
  // zoom point's own tables come back bit for bit there.
  const std::size_t n = zoom_counts_.size();
  if (!(zoom_counts > zoom_counts_.front()))
    return {0, 0.0, zoom_counts < zoom_counts_.front() || std::isnan(zoom_counts)};
  if (!(zoom_counts < zoom_counts_.back()))
    return {n - 2, 1.0, zoom_counts > zoom_counts_.back()};
  const std::size_t k =
      std::size_t(std::upper_bound(zoom_counts_.begin(), zoom_counts_.end(), zoom_counts) -
                  zoom_counts_.begin()) -
      1;
  return {k, (zoom_counts - zoom_counts_[k]) / (zoom_counts_[k + 1] - zoom_counts_[k]), false};
}

MonotoneCurve::Result LensProfile::focus_diopters(double zoom_counts, double focus_counts) const {
  if (!has_per_zoom_focus())
    return focus_diopters_(focus_counts);
  // Each table in diopters, then the diopters blended across zoom. With both
  // tables non-increasing (or both non-decreasing) in counts, so is
  // (1 - t) a + t b for a fixed t in [0, 1], and in floating point too: a
  // product by a fixed non-negative weight and a sum both round monotonically.
  // Infinity (0 D) blends with 0 D to exactly 0 D, and two non-negative
  // diopters never blend to a negative one.
  const ZoomSpan s = zoom_span(zoom_counts);
  const MonotoneCurve::Result a = zoom_points_[s.k].focus(focus_counts);
  if (s.t == 0.0)
    return {a.y, a.clamped || s.clamped};
  const MonotoneCurve::Result b = zoom_points_[s.k + 1].focus(focus_counts);
  if (s.t == 1.0)
    return {b.y, b.clamped || s.clamped};
  return {(1.0 - s.t) * a.y + s.t * b.y, a.clamped || b.clamped || s.clamped};
}

MonotoneCurve::Result LensProfile::rest_focus_diopters(double zoom_counts) const {
  // The far end: the table end with the smaller diopter value.
  const auto far = [](const MonotoneCurve &c) { return std::min(c.ys().front(), c.ys().back()); };
  if (!has_per_zoom_focus())
    return {far(focus_diopters_), false};
  const ZoomSpan s = zoom_span(zoom_counts);
  const double a = far(zoom_points_[s.k].focus);
  if (s.t == 0.0)
    return {a, s.clamped};
  const double b = far(zoom_points_[s.k + 1].focus);
  if (s.t == 1.0)
    return {b, s.clamped};
  return {(1.0 - s.t) * a + s.t * b, s.clamped};
}

LensProfile::Lookup LensProfile::focus_distance_m(double zoom_counts, double focus_counts) const {
  const auto r = focus_diopters(zoom_counts, focus_counts);
  return {from_diopters(r.y), r.clamped};
}

LensProfile::Lookup LensProfile::focus_distance_m(double focus_counts) const {
  return focus_distance_m(zoom_counts_.front(), focus_counts);
}

LensProfile::Lookup LensProfile::f_number(double iris_counts) const {
  const auto r = iris_stops_(iris_counts);
  return {from_stops(r.y), r.clamped};
}

std::optional<LensProfile::Lookup> LensProfile::t_stop(double iris_counts) const {
  if (t_stop_stops_.empty())
    return std::nullopt;
  const auto r = t_stop_stops_(iris_counts);
  return Lookup{from_stops(r.y), r.clamped};
}

LensProfile::Lookup LensProfile::focal_length_mm(double zoom_counts) const {
  if (!is_zoom())
    return {zoom_points_.front().focal_length_mm, false};
  const auto r = log_focal_length_(zoom_counts);
  // At a calibration point (or clamped to an end one) return the file's value
  // itself: exp(log(f)) can be an ulp off, and "reproduces calibration points
  // exactly" is a promise.
  const double z = std::clamp(zoom_counts, zoom_counts_.front(), zoom_counts_.back());
  const auto it = std::find(zoom_counts_.begin(), zoom_counts_.end(), z);
  if (it != zoom_counts_.end())
    return {zoom_points_[std::size_t(it - zoom_counts_.begin())].focal_length_mm, r.clamped};
  return {std::exp(r.y), r.clamped};
}

LensProfile::Lookup LensProfile::entrance_pupil_offset_mm(double zoom_counts) const {
  if (!is_zoom())
    return {zoom_points_.front().entrance_pupil_offset_mm, false};
  const auto r = entrance_pupil_mm_(zoom_counts);
  return {r.y, r.clamped};
}

LensProfile::CameraPoint LensProfile::CameraTable::at(double d) const {
  if (points.size() == 1)
    return points.front();
  CameraPoint out;
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = curves[i](d).y;
  return out;
}

LensProfile::CameraPoint LensProfile::camera_for_focus(double zoom_counts, double diopters) const {
  const ZoomSpan s = zoom_span(zoom_counts);
  const CameraPoint a = zoom_points_[s.k].camera->at(diopters);
  if (s.t == 0.0)
    return a;
  const CameraPoint b = zoom_points_[s.k + 1].camera->at(diopters);
  if (s.t == 1.0)
    return b;
  CameraPoint out;
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = (1.0 - s.t) * a[i] + s.t * b[i];
  return out;
}

double LensProfile::projection_at_point(const ZoomPoint &z, double diopters) const {
  // Version 3: the camera model's image scale, fx, on the sensor.
  if (z.camera)
    return z.camera->at(diopters)[kFx] * image_->sensor_width_mm / double(image_->width_px);
  if (!z.breathing.empty())
    return z.breathing(diopters).y;
  return z.projection_focal_length_mm.value_or(z.focal_length_mm);
}

LensProfile::Lookup LensProfile::projection_focal_length_mm(double zoom_counts,
                                                            double focus_counts) const {
  return projection_for_focus(zoom_counts, focus_diopters(zoom_counts, focus_counts));
}

LensProfile::Lookup LensProfile::projection_for_focus(double zoom_counts,
                                                      MonotoneCurve::Result focus) const {
  if (!is_zoom())
    return {projection_at_point(zoom_points_.front(), focus.y), focus.clamped};

  // Blend the breathing of the two zoom points around the current zoom as a
  // ratio to their nominal focal length, then scale by the interpolated focal
  // length: breathing is a relative change of image scale, and the ratio
  // varies far more smoothly with zoom than the absolute value does.
  const Lookup f = focal_length_mm(zoom_counts);
  const ZoomSpan s = zoom_span(zoom_counts);
  const ZoomPoint &a = zoom_points_[s.k], &b = zoom_points_[s.k + 1];
  if (s.t == 0.0)
    return {projection_at_point(a, focus.y), f.clamped || focus.clamped};
  if (s.t == 1.0)
    return {projection_at_point(b, focus.y), f.clamped || focus.clamped};
  const double ratio = (1.0 - s.t) * projection_at_point(a, focus.y) / a.focal_length_mm +
                       s.t * projection_at_point(b, focus.y) / b.focal_length_mm;
  return {f.value * ratio, f.clamped || focus.clamped};
}

double LensProfile::rest_counts_iris() const {
  const auto &xs = iris_stops_.xs();
  const auto &ys = iris_stops_.ys();
  return ys.front() <= ys.back() ? xs.front() : xs.back();
}

LensState LensProfile::evaluate(const LensCounts &counts, const LensValues &values) const {
  const AxisReading rest_focus{0.0, 0, false}; // its value: rest_focus_diopters
  const AxisReading rest_iris{rest_counts_iris(), 0, false};
  const AxisReading rest_zoom{zoom_counts_.front(), 0, false};
  // An axis with counts takes them; one with a value alone, that value.
  const std::optional<AxisReading> focus_value =
      counts.focus ? std::nullopt : values.focus_diopters;
  const std::optional<AxisReading> iris_value = counts.iris ? std::nullopt : values.iris_stops;
  const std::optional<AxisReading> zoom_value =
      counts.zoom ? std::nullopt : values.log_focal_length;
  const AxisReading &fo = counts.focus ? *counts.focus : focus_value ? *focus_value : rest_focus;
  const AxisReading &ir = counts.iris ? *counts.iris : iris_value ? *iris_value : rest_iris;
  // A prime has no zoom axis: its zoom quantities are as fresh as focus.
  const AxisReading zo = zoom_value
                             ? AxisReading{rest_zoom.counts, zoom_value->t_ns, zoom_value->fresh}
                         : !is_zoom()  ? AxisReading{rest_zoom.counts, fo.t_ns, fo.fresh}
                         : counts.zoom ? *counts.zoom
                                       : rest_zoom;

  const auto measured = [](Lookup l, const AxisReading &a) {
    return Measured{l.value, a.t_ns, a.fresh, l.clamped};
  };
  LensState s;
  s.calibrated = calibrated_ || (focus_value && iris_value && zoom_value);
  const MonotoneCurve::Result focus = counts.focus ? focus_diopters(zo.counts, fo.counts)
                                      : focus_value
                                          ? MonotoneCurve::Result{focus_value->counts, false}
                                          : rest_focus_diopters(zo.counts);
  const Lookup focus_m{from_diopters(focus.y), focus.clamped};
  // With per-zoom tables focus depends on zoom too: as old as the older
  // reading, fresh only if both are (like the projection focal length).
  s.focus_distance_m = has_per_zoom_focus() && !focus_value
                           ? Measured{focus_m.value, std::min(fo.t_ns, zo.t_ns),
                                      fo.fresh && zo.fresh, focus_m.clamped}
                           : measured(focus_m, fo);
  if (iris_value) {
    s.f_number = measured({std::exp2(0.5 * iris_value->counts), false}, ir);
  } else {
    s.f_number = measured(f_number(ir.counts), ir);
    if (const auto t = t_stop(ir.counts))
      s.t_stop = measured(*t, ir);
  }
  s.entrance_pupil_offset_mm = measured(entrance_pupil_offset_mm(zo.counts), zo);
  if (zoom_value) {
    const double mm = std::exp(zoom_value->counts);
    s.focal_length_mm = measured({mm, false}, zo);
    s.projection_focal_length_mm =
        Measured{mm, std::min(fo.t_ns, zo.t_ns), fo.fresh && zo.fresh, false};
  } else {
    s.focal_length_mm = measured(focal_length_mm(zo.counts), zo);
    // Depends on focus and zoom: as old as the older one, fresh only if both are.
    const Lookup proj = projection_for_focus(zo.counts, focus);
    s.projection_focal_length_mm =
        Measured{proj.value, std::min(fo.t_ns, zo.t_ns), fo.fresh && zo.fresh, proj.clamped};
  }
  s.distortion = distortion_;
  if (image_) {
    const CameraPoint c = camera_for_focus(zo.counts, focus.y);
    s.projection = {(c[kCx] + 0.5) / double(image_->width_px),
                    (c[kCy] + 0.5) / double(image_->height_px), c[kFy] / c[kFx]};
    s.distortion = Distortion{c[kK1], c[kK2], c[kK3], c[kP1], c[kP2]};
  }
  return s;
}

} // namespace camhead::lens_control
