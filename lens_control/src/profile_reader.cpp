// The strict profile reader: every field is checked for presence, type,
// finiteness and range, unknown fields are rejected, and each table must have
// strictly increasing counts and a strictly monotone quantity. The first
// problem found is thrown as ProfileError("FILE: FIELD: REASON"), by base's
// strict JSON reader (config_json.h) or by the rules below. A profile
// that would make the renderer's focus run backwards between two calibration
// marks is a configuration error, not something to smooth over.
//
// The version names the layout, so that an older reader refuses what it
// cannot read instead of misreading it: version 1 has one top-level focus
// table, version 2 one table on every zoom point and none at the top, and
// version 3 a camera model on every zoom point, with its focus tables as
// version 1's or 2's (README.md, "Profile format").
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "camhead/base/config_json.h"
#include "camhead/lens_control/lens_profile.h"

namespace camhead::lens_control {

namespace {

using base::JsonValue;
using base::Range;

constexpr std::string_view kFormat = "camhead-lens-profile";
constexpr std::int64_t kVersionOneFocus = 1;     // one top-level focus table
constexpr std::int64_t kVersionPerZoomFocus = 2; // a focus table on every zoom point
constexpr std::int64_t kVersionCameraModel = 3;  // a camera model on every zoom point

// Strictly monotone in either direction; returns the index of the first
// element that breaks it, or 0 when the sequence is monotone.
std::size_t first_non_monotone(const std::vector<double> &v) {
  const double dir = v[1] - v[0];
  if (dir == 0.0)
    return 1;
  for (std::size_t i = 1; i < v.size(); ++i)
    if (!((v[i] - v[i - 1]) * dir > 0.0))
      return i;
  return 0;
}

// Encoder counts: a JSON integer in the int32 range encoders report in.
double counts(const JsonValue &v) {
  return double(v.integer(std::numeric_limits<std::int32_t>::min(),
                          std::numeric_limits<std::int32_t>::max()));
}

// A distance in metres or "infinity", returned in diopters.
double diopters(const JsonValue &v) {
  if (v.json().is_string()) {
    if (v.json().get<std::string>() != "infinity")
      v.fail("must be a distance in metres or \"infinity\"");
    return 0.0;
  }
  if (!v.json().is_number())
    v.fail("must be a distance in metres or \"infinity\"");
  // Nothing focuses closer than a millimetre; 1/d of a smaller positive
  // number (1e-310) overflows to infinity, which no curve can hold.
  return 1.0 / v.number(Range::within(1e-3, 1e5));
}

// A calibration table: an array of at least 2 points.
std::vector<JsonValue> table(const JsonValue &v) {
  const std::vector<JsonValue> points = v.elements("calibration points");
  if (points.size() < 2)
    v.fail("needs at least 2 calibration points, has " + std::to_string(points.size()));
  return points;
}

// Counts column of a table: strictly increasing, so that every count maps
// to one value.
std::vector<double> count_column(const std::vector<JsonValue> &t) {
  std::vector<double> xs;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const JsonValue c = t[i].at("counts");
    xs.push_back(counts(c));
    if (i > 0 && !(xs[i] > xs[i - 1]))
      c.fail("must be greater than " + t[i - 1].at("counts").field() +
             " (counts strictly increasing)");
  }
  return xs;
}

void require_monotone(const std::vector<double> &v, const std::vector<JsonValue> &t,
                      std::string_view key) {
  if (const std::size_t i = first_non_monotone(v))
    t[i].fail_member(key, "not strictly monotone (a " + std::string(key) +
                              " table must rise or fall throughout, no repeats)");
}

} // namespace

class ProfileReader {
public:
  LensProfile read(const JsonValue &root) {
    root.object({"format", "version", "name", "iris"},
                {"description", "focus", "zoom", "prime", "distortion", "image"});
    const JsonValue format = root.at("format");
    if (!format.json().is_string() || format.json().get<std::string>() != kFormat)
      format.fail("must be \"" + std::string(kFormat) + "\"");
    const JsonValue version = root.at("version");
    const Json &v = version.json();
    if (!v.is_number_integer() || (v.get<std::int64_t>() != kVersionOneFocus &&
                                   v.get<std::int64_t>() != kVersionPerZoomFocus &&
                                   v.get<std::int64_t>() != kVersionCameraModel))
      version.fail("unsupported version (this reader understands 1, 2 and 3)");
    camera_model_ = v.get<std::int64_t>() == kVersionCameraModel;
    // Version 3 takes either focus layout, told apart by where the tables are.
    per_zoom_focus_ = v.get<std::int64_t>() == kVersionPerZoomFocus ||
                      (camera_model_ && root.has("zoom") && !root.has("focus"));
    LensProfile p;
    if (camera_model_) {
      p.image_ = read_image(root.at("image"));
      image_ = *p.image_;
      if (root.has("distortion"))
        root.fail_member("distortion", "a version 3 profile gives the distortion with each "
                                       "camera point (zoom[i].camera or prime.camera)");
    } else if (root.has("image")) {
      root.fail_member("image", "belongs to a camera model, which needs \"version\": 3");
    }
    p.name_ = root.at("name").string();
    if (root.has("description"))
      (void)root.at("description").text();

    if (per_zoom_focus_ && root.has("focus") && !camera_model_)
      version.fail("2 means a focus table on every zoom point (zoom[i].focus) and no "
                   "top-level focus; a profile with one focus table is version 1");
    if (!per_zoom_focus_)
      p.focus_diopters_ = read_focus(root.at("focus"));
    read_iris(root.at("iris"), p);
    const bool zoom = root.has("zoom"), prime = root.has("prime");
    if (zoom == prime)
      root.fail_member(zoom ? "prime" : "zoom",
                       zoom ? "a profile has either zoom or prime, not both"
                            : "missing (give zoom for a zoom lens, prime for a prime)");
    if (per_zoom_focus_ && prime && !camera_model_)
      version.fail("2 means per-zoom focus tables, which need a zoom table; a prime has "
                   "one top-level focus table and is version 1");
    if (zoom)
      read_zoom(root.at("zoom"), p);
    else
      p.zoom_points_ = {read_zoom_point(root.at("prime"), false, nullptr)};
    if (prime)
      p.zoom_counts_ = {0.0};
    if (root.has("distortion"))
      p.distortion_ = read_distortion(root.at("distortion"));
    return p;
  }

private:
  using Json = base::Json;

  // A focus table, top-level ("focus") or of one zoom point ("zoom[2].focus").
  static MonotoneCurve read_focus(const JsonValue &v) {
    const std::vector<JsonValue> t = table(v);
    for (const JsonValue &point : t)
      point.object({"counts", "distance_m"});
    const std::vector<double> xs = count_column(t);
    std::vector<double> d;
    for (const JsonValue &point : t)
      d.push_back(diopters(point.at("distance_m")));
    require_monotone(d, t, "distance_m");
    return MonotoneCurve(xs, d);
  }

  static void read_iris(const JsonValue &v, LensProfile &p) {
    const std::vector<JsonValue> t = table(v);
    for (const JsonValue &point : t)
      point.object({"counts", "f_number"}, {"t_stop"});
    const std::vector<double> xs = count_column(t);
    std::vector<double> n, ts;
    const bool any_t = t[0].has("t_stop");
    for (const JsonValue &point : t) {
      const double fn = point.at("f_number").number(Range::within(0.5, 128.0));
      n.push_back(2.0 * std::log2(fn));
      if (point.has("t_stop") != any_t)
        point.fail_member("t_stop", "give t_stop on every iris point or on none");
      if (any_t) {
        const JsonValue t_stop = point.at("t_stop");
        const double tv = t_stop.number(Range::within(0.5, 256.0));
        if (tv < fn)
          t_stop.fail("must be " + Range::at_least(fn).describe() +
                      " (f_number): a T-stop includes transmission losses");
        ts.push_back(2.0 * std::log2(tv));
      }
    }
    require_monotone(n, t, "f_number");
    p.iris_stops_ = MonotoneCurve(xs, n);
    if (any_t) {
      require_monotone(ts, t, "t_stop");
      p.t_stop_stops_ = MonotoneCurve(xs, ts);
    }
  }

  // One zoom calibration point (in_table, with counts), or the prime object.
  // `first`, for zoom points after the first, is that first point: the rest
  // must give the same optional fields (a table with holes cannot be
  // interpolated).
  LensProfile::ZoomPoint read_zoom_point(const JsonValue &d, bool in_table,
                                         const LensProfile::ZoomPoint *first) const {
    if (in_table)
      d.object({"counts", "focal_length_mm"},
               {"projection_focal_length_mm", "entrance_pupil_offset_mm", "focus", "camera"});
    else
      d.object({"focal_length_mm"},
               {"projection_focal_length_mm", "entrance_pupil_offset_mm", "camera"});
    if (camera_model_ && !d.has("camera"))
      d.fail_member("camera", "missing (a version 3 profile gives a camera model on every zoom "
                              "point, or on the prime)");
    if (!camera_model_ && d.has("camera"))
      d.fail_member("camera", "a camera model needs \"version\": 3 (and the \"image\" it was "
                              "calibrated in)");
    if (d.has("camera") && d.has("projection_focal_length_mm"))
      d.fail_member("projection_focal_length_mm",
                    "a camera model's fx sets the image scale; give one or the other");
    LensProfile::ZoomPoint z;
    z.focal_length_mm = d.at("focal_length_mm").number(Range::above(0.0, 1e4));
    const bool pupil = d.has("entrance_pupil_offset_mm");
    const bool proj = d.has("projection_focal_length_mm");
    if (first && pupil != first->has_pupil)
      d.fail_member("entrance_pupil_offset_mm", "give it on every zoom point or on none");
    if (first && proj != first->has_projection)
      d.fail_member("projection_focal_length_mm", "give it on every zoom point or on none");
    z.has_pupil = pupil;
    z.has_projection = proj;
    if (pupil)
      z.entrance_pupil_offset_mm =
          d.at("entrance_pupil_offset_mm").number(Range::within(-1e3, 1e3));
    if (proj) {
      const JsonValue v = d.at("projection_focal_length_mm");
      if (v.json().is_array())
        z.breathing = read_breathing(v);
      else
        z.projection_focal_length_mm = v.number(Range::above(0.0, 1e4));
    }
    if (camera_model_)
      z.camera = read_camera(d.at("camera"));
    if (in_table) {
      if (d.has("focus") && !per_zoom_focus_)
        d.fail_member("focus", "per-zoom focus tables need \"version\": 2 (then one on every "
                               "zoom point, and no top-level focus)");
      if (!d.has("focus") && per_zoom_focus_)
        d.fail_member("focus",
                      "missing (a version 2 profile gives a focus table on every zoom point)");
      if (per_zoom_focus_)
        z.focus = read_focus(d.at("focus"));
    }
    return z;
  }

  // Focus breathing: projection focal length over focus distance.
  static MonotoneCurve read_breathing(const JsonValue &v) {
    const std::vector<JsonValue> t = table(v);
    std::vector<double> d, p;
    for (const JsonValue &point : t) {
      point.object({"distance_m", "projection_focal_length_mm"});
      d.push_back(diopters(point.at("distance_m")));
      p.push_back(point.at("projection_focal_length_mm").number(Range::above(0.0, 1e4)));
    }
    require_monotone(d, t, "distance_m");
    // MonotoneCurve wants increasing x: list near-to-far becomes far-to-near.
    if (d.front() > d.back()) {
      std::reverse(d.begin(), d.end());
      std::reverse(p.begin(), p.end());
    }
    return MonotoneCurve(d, p);
  }

  void read_zoom(const JsonValue &v, LensProfile &p) const {
    const std::vector<JsonValue> t = table(v);
    for (std::size_t i = 0; i < t.size(); ++i)
      p.zoom_points_.push_back(
          read_zoom_point(t[i], true, i == 0 ? nullptr : &p.zoom_points_.front()));
    p.zoom_counts_ = count_column(t);
    std::vector<double> logf, pupil;
    for (const auto &z : p.zoom_points_) {
      logf.push_back(std::log(z.focal_length_mm));
      pupil.push_back(z.entrance_pupil_offset_mm);
    }
    require_monotone(logf, t, "focal_length_mm");
    if (per_zoom_focus_)
      require_same_direction(p.zoom_points_, t);
    p.log_focal_length_ = MonotoneCurve(p.zoom_counts_, logf);
    p.entrance_pupil_mm_ = MonotoneCurve(p.zoom_counts_, pupil);
  }

  // Blending two focus tables keeps the direction they share (lens_profile.cpp,
  // focus_diopters); two tables of opposite directions would blend into a
  // focus that runs backwards somewhere between their zoom points.
  static void require_same_direction(const std::vector<LensProfile::ZoomPoint> &zs,
                                     const std::vector<JsonValue> &t) {
    const auto rising = [](const MonotoneCurve &c) { return c.ys().back() > c.ys().front(); };
    const auto how = [](bool r) {
      return std::string(r ? "distance falls as counts rise" : "distance rises as counts rise");
    };
    const bool first = rising(zs.front().focus);
    for (std::size_t i = 1; i < zs.size(); ++i)
      if (rising(zs[i].focus) != first)
        t[i].at("focus").fail("runs the other way from " + t[0].at("focus").field() + " (" +
                              how(rising(zs[i].focus)) + " here, " + how(first) +
                              " there): every zoom point's focus table must run the same way, "
                              "or the blend between them would run backwards");
  }

  // The images the camera tables were calibrated in.
  static LensProfile::Image read_image(const JsonValue &v) {
    v.object({"width_px", "height_px", "sensor_width_mm"});
    LensProfile::Image image;
    image.width_px = int(v.at("width_px").integer(1, 1 << 16));
    image.height_px = int(v.at("height_px").integer(1, 1 << 16));
    image.sensor_width_mm = v.at("sensor_width_mm").number(Range::above(0.0, 1e3));
    return image;
  }

  // A camera table: OpenCV's model over focus distance, at least one point.
  LensProfile::CameraTable read_camera(const JsonValue &v) const {
    const std::vector<JsonValue> t = v.elements("camera points");
    if (t.empty())
      v.fail("needs at least 1 camera point");
    LensProfile::CameraTable table;
    const double w = image_.width_px, h = image_.height_px;
    for (const JsonValue &point : t) {
      point.object({"distance_m", "fx", "fy", "cx", "cy"}, {"k1", "k2", "k3", "p1", "p2"});
      table.diopters.push_back(diopters(point.at("distance_m")));
      LensProfile::CameraPoint c{};
      c[LensProfile::kFx] = point.at("fx").number(Range::above(0.0, 1e6));
      c[LensProfile::kFy] = point.at("fy").number(Range::above(0.0, 1e6));
      // The principal point within the image (OpenCV's pixel centres).
      c[LensProfile::kCx] = point.at("cx").number(Range::within(-0.5, w - 0.5));
      c[LensProfile::kCy] = point.at("cy").number(Range::within(-0.5, h - 0.5));
      const auto coefficient = [&](std::string_view k, LensProfile::CameraParam i) {
        if (point.has(k))
          c[i] = point.at(k).number(Range::within(-100.0, 100.0));
      };
      coefficient("k1", LensProfile::kK1);
      coefficient("k2", LensProfile::kK2);
      coefficient("p1", LensProfile::kP1);
      coefficient("p2", LensProfile::kP2);
      coefficient("k3", LensProfile::kK3);
      table.points.push_back(c);
    }
    if (t.size() > 1)
      require_monotone(table.diopters, t, "distance_m");
    // MonotoneCurve wants increasing x: near-to-far becomes far-to-near.
    if (table.diopters.front() > table.diopters.back()) {
      std::reverse(table.diopters.begin(), table.diopters.end());
      std::reverse(table.points.begin(), table.points.end());
    }
    if (table.points.size() > 1)
      for (std::size_t i = 0; i < LensProfile::kCameraParams; ++i) {
        std::vector<double> ys;
        for (const LensProfile::CameraPoint &c : table.points)
          ys.push_back(c[i]);
        table.curves[i] = MonotoneCurve(table.diopters, ys);
      }
    return table;
  }

  static Distortion read_distortion(const JsonValue &d) {
    d.object({}, {"k1", "k2", "k3", "p1", "p2"});
    Distortion out;
    const auto coef = [&](std::string_view k, double &v) {
      if (d.has(k))
        v = d.at(k).number(Range::within(-100.0, 100.0));
    };
    coef("k1", out.k1);
    coef("k2", out.k2);
    coef("k3", out.k3);
    coef("p1", out.p1);
    coef("p2", out.p2);
    return out;
  }

  bool per_zoom_focus_ = false; // version 2, or 3 with per-zoom tables
  bool camera_model_ = false;   // version 3
  LensProfile::Image image_;    // version 3
};

LensProfile LensProfile::parse(std::string_view json_text, const std::filesystem::path &source) {
  try {
    const base::JsonFile json(json_text, source.string());
    return ProfileReader().read(json.root());
  } catch (const base::ConfigError &e) {
    throw ProfileError(e);
  }
}

LensProfile LensProfile::load(const std::filesystem::path &path) {
  std::string text;
  try {
    text = base::read_config_file(path);
  } catch (const base::ConfigError &e) {
    throw ProfileError(e);
  }
  return parse(text, path);
}

} // namespace camhead::lens_control
