// The strict profile reader: every field is checked for presence, type,
// finiteness and range, unknown fields are rejected, and each table must have
// strictly increasing counts and a strictly monotone quantity. The first
// problem found is thrown as ProfileError("FILE: FIELD: REASON"). A profile
// that would make the renderer's focus run backwards between two calibration
// marks is a configuration error, not something to smooth over.
//
// The version names the focus layout, one layout per version, so that an
// older reader refuses what it cannot read instead of misreading it: version 1
// has one top-level focus table, version 2 one table on every zoom point and
// none at the top (README.md, "Profile format").
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "camhead/lens_control/lens_profile.h"

namespace camhead::lens_control {

namespace {

using Json = nlohmann::json;
using Keys = std::initializer_list<std::string_view>;

constexpr std::string_view kFormat = "camhead-lens-profile";
constexpr std::int64_t kVersionOneFocus = 1;     // one top-level focus table
constexpr std::int64_t kVersionPerZoomFocus = 2; // a focus table on every zoom point

std::string child(const std::string &field, std::string_view key) {
  return field.empty() ? std::string(key) : field + "." + std::string(key);
}

std::string index(const std::string &field, std::size_t i) {
  return field + "[" + std::to_string(i) + "]";
}

std::string show(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

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

} // namespace

class ProfileReader {
public:
  explicit ProfileReader(std::string file) : file_(std::move(file)) {}

  LensProfile read(const Json &root) {
    keys(root, "", {"format", "version", "name", "iris"},
         {"description", "focus", "zoom", "prime", "distortion"});
    if (!root.at("format").is_string() || root.at("format").get<std::string>() != kFormat)
      fail("format", "must be \"" + std::string(kFormat) + "\"");
    const Json &version = root.at("version");
    if (!version.is_number_integer() || (version.get<std::int64_t>() != kVersionOneFocus &&
                                         version.get<std::int64_t>() != kVersionPerZoomFocus))
      fail("version", "unsupported version (this reader understands 1 and 2)");
    per_zoom_focus_ = version.get<std::int64_t>() == kVersionPerZoomFocus;
    if (!root.at("name").is_string() || root.at("name").get<std::string>().empty())
      fail("name", "must be a non-empty string");
    if (root.contains("description") && !root.at("description").is_string())
      fail("description", "must be a string");

    LensProfile p;
    p.name_ = root.at("name").get<std::string>();
    if (per_zoom_focus_ && root.contains("focus"))
      fail("version", "2 means a focus table on every zoom point (zoom[i].focus) and no "
                      "top-level focus; a profile with one focus table is version 1");
    if (!per_zoom_focus_ && !root.contains("focus"))
      fail("focus", "missing");
    if (!per_zoom_focus_)
      p.focus_diopters_ = read_focus(root.at("focus"), "focus");
    read_iris(root.at("iris"), p);
    const bool zoom = root.contains("zoom"), prime = root.contains("prime");
    if (zoom == prime)
      fail(zoom ? "prime" : "zoom", zoom
                                        ? "a profile has either zoom or prime, not both"
                                        : "missing (give zoom for a zoom lens, prime for a prime)");
    if (per_zoom_focus_ && prime)
      fail("version", "2 means per-zoom focus tables, which need a zoom table; a prime has "
                      "one top-level focus table and is version 1");
    if (zoom)
      read_zoom(root.at("zoom"), p);
    else
      p.zoom_points_ = {read_zoom_point(root.at("prime"), "prime", false, nullptr)};
    if (prime)
      p.zoom_counts_ = {0.0};
    if (root.contains("distortion"))
      p.distortion_ = read_distortion(root.at("distortion"), "distortion");
    return p;
  }

private:
  [[noreturn]] void fail(const std::string &field, const std::string &reason) const {
    throw ProfileError(file_, field, reason);
  }

  void keys(const Json &d, const std::string &field, Keys required, Keys optional = {}) const {
    if (!d.is_object())
      fail(field, "must be an object");
    for (const std::string_view k : required)
      if (!d.contains(k))
        fail(child(field, k), "missing");
    const auto listed = [](Keys ks, const std::string &k) {
      return std::find(ks.begin(), ks.end(), k) != ks.end();
    };
    for (const auto &[k, v] : d.items())
      if (!listed(required, k) && !listed(optional, k))
        fail(child(field, k), "unknown field");
  }

  double number(const Json &v, const std::string &field, double lo, double hi,
                bool lo_open = false) const {
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      fail(field, "must be a finite number");
    const double x = v.get<double>();
    if (lo_open ? !(x > lo) : !(x >= lo))
      fail(field, "must be " + std::string(lo_open ? "> " : ">= ") + show(lo));
    if (x > hi)
      fail(field, "must be <= " + show(hi));
    return x;
  }

  // Encoder counts: a JSON integer in the int32 range encoders report in.
  double counts(const Json &v, const std::string &field) const {
    if (!v.is_number_integer())
      fail(field, "must be an integer");
    constexpr auto lo = std::numeric_limits<std::int32_t>::min();
    constexpr auto hi = std::numeric_limits<std::int32_t>::max();
    if ((v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(hi)) ||
        v.get<std::int64_t>() > hi || v.get<std::int64_t>() < lo)
      fail(field, "must be within the 32-bit encoder range");
    return double(v.get<std::int64_t>());
  }

  // A distance in metres or "infinity", returned in diopters.
  double diopters(const Json &v, const std::string &field) const {
    if (v.is_string()) {
      if (v.get<std::string>() != "infinity")
        fail(field, "must be a distance in metres or \"infinity\"");
      return 0.0;
    }
    if (!v.is_number())
      fail(field, "must be a distance in metres or \"infinity\"");
    return 1.0 / number(v, field, 0.0, 1e5, true);
  }

  const Json &table(const Json &v, const std::string &field) const {
    if (!v.is_array())
      fail(field, "must be an array of calibration points");
    if (v.size() < 2)
      fail(field, "needs at least 2 calibration points, has " + std::to_string(v.size()));
    return v;
  }

  // Counts column of a table: strictly increasing, so that every count maps
  // to one value.
  std::vector<double> count_column(const Json &t, const std::string &field) const {
    std::vector<double> xs;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const std::string f = index(field, i);
      xs.push_back(counts(t[i].at("counts"), child(f, "counts")));
      if (i > 0 && !(xs[i] > xs[i - 1]))
        fail(child(f, "counts"), "must be greater than " + child(index(field, i - 1), "counts") +
                                     " (counts strictly increasing)");
    }
    return xs;
  }

  void require_monotone(const std::vector<double> &v, const std::string &field,
                        std::string_view key) const {
    if (const std::size_t i = first_non_monotone(v))
      fail(child(index(field, i), key), "not strictly monotone (a " + std::string(key) +
                                            " table must rise or fall throughout, no repeats)");
  }

  // A focus table, top-level ("focus") or of one zoom point ("zoom[2].focus").
  MonotoneCurve read_focus(const Json &t, const std::string &field) const {
    table(t, field);
    for (std::size_t i = 0; i < t.size(); ++i)
      keys(t[i], index(field, i), {"counts", "distance_m"});
    const std::vector<double> xs = count_column(t, field);
    std::vector<double> d;
    for (std::size_t i = 0; i < t.size(); ++i)
      d.push_back(diopters(t[i].at("distance_m"), child(index(field, i), "distance_m")));
    require_monotone(d, field, "distance_m");
    return MonotoneCurve(xs, d);
  }

  void read_iris(const Json &t, LensProfile &p) const {
    table(t, "iris");
    for (std::size_t i = 0; i < t.size(); ++i)
      keys(t[i], index("iris", i), {"counts", "f_number"}, {"t_stop"});
    const std::vector<double> xs = count_column(t, "iris");
    std::vector<double> n, ts;
    const bool any_t = t[0].contains("t_stop");
    for (std::size_t i = 0; i < t.size(); ++i) {
      const std::string f = index("iris", i);
      const double fn = number(t[i].at("f_number"), child(f, "f_number"), 0.5, 128.0);
      n.push_back(2.0 * std::log2(fn));
      if (t[i].contains("t_stop") != any_t)
        fail(child(f, "t_stop"), "give t_stop on every iris point or on none");
      if (any_t) {
        const double tv = number(t[i].at("t_stop"), child(f, "t_stop"), 0.5, 256.0);
        if (tv < fn)
          fail(child(f, "t_stop"),
               "must be >= f_number (" + show(fn) + "): a T-stop includes transmission losses");
        ts.push_back(2.0 * std::log2(tv));
      }
    }
    require_monotone(n, "iris", "f_number");
    p.iris_stops_ = MonotoneCurve(xs, n);
    if (any_t) {
      require_monotone(ts, "iris", "t_stop");
      p.t_stop_stops_ = MonotoneCurve(xs, ts);
    }
  }

  // One zoom calibration point (in_table, with counts), or the prime object.
  // `first`, for zoom points after the first, is that first point: the rest
  // must give the same optional fields (a table with holes cannot be
  // interpolated).
  LensProfile::ZoomPoint read_zoom_point(const Json &d, const std::string &field, bool in_table,
                                         const LensProfile::ZoomPoint *first) const {
    if (in_table)
      keys(d, field, {"counts", "focal_length_mm"},
           {"projection_focal_length_mm", "entrance_pupil_offset_mm", "focus"});
    else
      keys(d, field, {"focal_length_mm"},
           {"projection_focal_length_mm", "entrance_pupil_offset_mm"});
    LensProfile::ZoomPoint z;
    z.focal_length_mm =
        number(d.at("focal_length_mm"), child(field, "focal_length_mm"), 0.0, 1e4, true);
    const bool pupil = d.contains("entrance_pupil_offset_mm");
    const bool proj = d.contains("projection_focal_length_mm");
    if (first && pupil != first->has_pupil)
      fail(child(field, "entrance_pupil_offset_mm"), "give it on every zoom point or on none");
    if (first && proj != first->has_projection)
      fail(child(field, "projection_focal_length_mm"), "give it on every zoom point or on none");
    z.has_pupil = pupil;
    z.has_projection = proj;
    if (pupil)
      z.entrance_pupil_offset_mm = number(d.at("entrance_pupil_offset_mm"),
                                          child(field, "entrance_pupil_offset_mm"), -1e3, 1e3);
    if (proj) {
      const Json &v = d.at("projection_focal_length_mm");
      const std::string f = child(field, "projection_focal_length_mm");
      if (v.is_array())
        z.breathing = read_breathing(v, f);
      else
        z.projection_focal_length_mm = number(v, f, 0.0, 1e4, true);
    }
    if (in_table) {
      const std::string f = child(field, "focus");
      if (d.contains("focus") && !per_zoom_focus_)
        fail(f, "per-zoom focus tables need \"version\": 2 (then one on every zoom point, and "
                "no top-level focus)");
      if (!d.contains("focus") && per_zoom_focus_)
        fail(f, "missing (a version 2 profile gives a focus table on every zoom point)");
      if (per_zoom_focus_)
        z.focus = read_focus(d.at("focus"), f);
    }
    return z;
  }

  // Focus breathing: projection focal length over focus distance.
  MonotoneCurve read_breathing(const Json &t, const std::string &field) const {
    table(t, field);
    std::vector<double> d, p;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const std::string f = index(field, i);
      keys(t[i], f, {"distance_m", "projection_focal_length_mm"});
      d.push_back(diopters(t[i].at("distance_m"), child(f, "distance_m")));
      p.push_back(number(t[i].at("projection_focal_length_mm"),
                         child(f, "projection_focal_length_mm"), 0.0, 1e4, true));
    }
    require_monotone(d, field, "distance_m");
    // MonotoneCurve wants increasing x: list near-to-far becomes far-to-near.
    if (d.front() > d.back()) {
      std::reverse(d.begin(), d.end());
      std::reverse(p.begin(), p.end());
    }
    return MonotoneCurve(d, p);
  }

  void read_zoom(const Json &t, LensProfile &p) const {
    table(t, "zoom");
    for (std::size_t i = 0; i < t.size(); ++i) {
      const std::string f = index("zoom", i);
      p.zoom_points_.push_back(
          read_zoom_point(t[i], f, true, i == 0 ? nullptr : &p.zoom_points_.front()));
    }
    p.zoom_counts_ = count_column(t, "zoom");
    std::vector<double> logf, pupil;
    for (const auto &z : p.zoom_points_) {
      logf.push_back(std::log(z.focal_length_mm));
      pupil.push_back(z.entrance_pupil_offset_mm);
    }
    require_monotone(logf, "zoom", "focal_length_mm");
    if (per_zoom_focus_)
      require_same_direction(p.zoom_points_);
    p.log_focal_length_ = MonotoneCurve(p.zoom_counts_, logf);
    p.entrance_pupil_mm_ = MonotoneCurve(p.zoom_counts_, pupil);
  }

  // Blending two focus tables keeps the direction they share (lens_profile.cpp,
  // focus_diopters); two tables of opposite directions would blend into a
  // focus that runs backwards somewhere between their zoom points.
  void require_same_direction(const std::vector<LensProfile::ZoomPoint> &zs) const {
    const auto rising = [](const MonotoneCurve &c) { return c.ys().back() > c.ys().front(); };
    const auto how = [](bool r) {
      return std::string(r ? "distance falls as counts rise" : "distance rises as counts rise");
    };
    const bool first = rising(zs.front().focus);
    for (std::size_t i = 1; i < zs.size(); ++i)
      if (rising(zs[i].focus) != first)
        fail(child(index("zoom", i), "focus"),
             "runs the other way from zoom[0].focus (" + how(rising(zs[i].focus)) + " here, " +
                 how(first) +
                 " there): every zoom point's focus table must run the same way, or the "
                 "blend between them would run backwards");
  }

  Distortion read_distortion(const Json &d, const std::string &field) const {
    keys(d, field, {}, {"k1", "k2", "k3", "p1", "p2"});
    Distortion out;
    const auto coef = [&](std::string_view k, double &v) {
      if (d.contains(k))
        v = number(d.at(k), child(field, k), -100.0, 100.0);
    };
    coef("k1", out.k1);
    coef("k2", out.k2);
    coef("k3", out.k3);
    coef("p1", out.p1);
    coef("p2", out.p2);
    return out;
  }

  std::string file_;
  bool per_zoom_focus_ = false; // version 2
};

LensProfile LensProfile::parse(std::string_view json_text, const std::filesystem::path &source) {
  Json root;
  try {
    root = Json::parse(json_text);
  } catch (const Json::parse_error &e) {
    throw ProfileError(source.string(), "", std::string("invalid JSON: ") + e.what());
  }
  return ProfileReader(source.string()).read(root);
}

LensProfile LensProfile::load(const std::filesystem::path &path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw ProfileError(path.string(), "", "cannot open file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad())
    throw ProfileError(path.string(), "", "cannot read file");
  return parse(text.str(), path);
}

} // namespace camhead::lens_control
