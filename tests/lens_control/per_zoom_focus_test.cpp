// Per-zoom focus tables (profile format version 2): the bundled example loads;
// each zoom point's focus table comes back exactly at that zoom; at any fixed
// zoom the blended focus is monotone in focus counts; no jump across a zoom
// point; infinity survives blending; clamping; the lens state; a version 2
// profile with the same table everywhere matches the version 1 profile.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "camhead/lens_control/lens_profile.h"

#include <gtest/gtest.h>

namespace camhead::lens_control {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kExample =
    fs::path(CAMHEAD_SOURCE_DIR) / "scenes" / "lenses" / "example_zoom_24_70.json";
constexpr double kInf = std::numeric_limits<double>::infinity();

Json example() {
  std::ifstream in(kExample);
  return Json::parse(in);
}

LensProfile parse(const Json &j) {
  return LensProfile::parse(j.dump(), "/virtual/zoom.json");
}

double diopters(double distance_m) {
  return 1.0 / distance_m; // 1 / inf = 0
}

double distance(const Json &v) {
  return v.is_string() ? kInf : v.get<double>();
}

TEST(PerZoomFocus, ExampleReproducesEachZoomPointsTableExactly) {
  const Json j = example();
  const LensProfile p = LensProfile::load(kExample);
  EXPECT_TRUE(p.is_zoom());
  EXPECT_TRUE(p.has_per_zoom_focus());
  EXPECT_TRUE(p.has_t_stop());
  for (const Json &z : j["zoom"]) {
    const double zc = z["counts"].get<double>();
    EXPECT_EQ(p.focal_length_mm(zc).value, z["focal_length_mm"].get<double>());
    for (const Json &pt : z["focus"]) {
      const double fc = pt["counts"].get<double>();
      const double want = distance(pt["distance_m"]);
      const LensProfile::Lookup got = p.focus_distance_m(zc, fc);
      if (std::isinf(want))
        EXPECT_EQ(got.value, kInf) << "zoom " << zc << " focus " << fc;
      else
        EXPECT_LE(std::abs(got.value - want), 1e-12 * want) << "zoom " << zc << " focus " << fc;
      EXPECT_FALSE(got.clamped) << "zoom " << zc << " focus " << fc;
    }
  }
  // The one-argument lookup is the first zoom point's table.
  EXPECT_EQ(p.focus_distance_m(7600).value, kInf);
  EXPECT_EQ(p.focus_distance_m(7600).value, p.focus_distance_m(0, 7600).value);
}

// Zoom positions to test at: a dense grid, every calibration point and its
// immediate neighbours, and beyond both ends.
std::vector<double> zoom_positions(const Json &j) {
  std::vector<double> zs;
  for (double z = -200; z <= 3200; z += 12.5)
    zs.push_back(z);
  for (const Json &z : j["zoom"]) {
    const double c = z["counts"].get<double>();
    for (const double d : {-1.0, -1e-3, 0.0, 1e-3, 1.0})
      zs.push_back(c + d);
  }
  return zs;
}

TEST(PerZoomFocus, MonotoneInFocusCountsAtEveryZoom) {
  // Every table runs from close focus (low counts) to infinity (high counts),
  // so at any zoom the blend does too: non-decreasing everywhere (flat only
  // where every table it blends is clamped), strictly increasing inside the
  // calibrated range of every table (0.25-count steps).
  const Json j = example();
  const LensProfile p = LensProfile::load(kExample);
  double last_front = -kInf, first_back = kInf;
  for (const Json &z : j["zoom"]) {
    last_front = std::max(last_front, z["focus"].front()["counts"].get<double>());
    first_back = std::min(first_back, z["focus"].back()["counts"].get<double>());
  }
  std::size_t lookups = 0, not_monotone = 0, not_strict = 0, negative = 0;
  std::string first_bad;
  for (const double zc : zoom_positions(j)) {
    double prev = -1.0;
    for (double fc = -100; fc <= 8100; fc += 0.25, ++lookups) {
      const double d = p.focus_distance_m(zc, fc).value;
      if (!(d > 0.0))
        ++negative;
      if (d < prev || (d == prev && fc > last_front && fc <= first_back)) {
        (d < prev ? not_monotone : not_strict)++;
        if (first_bad.empty())
          first_bad = "zoom " + std::to_string(zc) + " focus " + std::to_string(fc);
      }
      prev = d;
    }
  }
  EXPECT_EQ(not_monotone, 0u) << first_bad;
  EXPECT_EQ(not_strict, 0u) << first_bad;
  EXPECT_EQ(negative, 0u);
  EXPECT_GT(lookups, 9'000'000u);
}

TEST(PerZoomFocus, ContinuousAcrossZoomWithNoJumpAtZoomPoints) {
  const Json j = example();
  const LensProfile p = LensProfile::load(kExample);
  // A Lipschitz bound in zoom: between zoom points k and k+1 the blend moves
  // by at most |D_k+1 - D_k| / (z_k+1 - z_k) per zoom count. With 1-count
  // steps over the whole zoom range, no step may exceed the largest such
  // slope: a jump at a zoom point would.
  const auto d_at = [&](double zc, double fc) {
    return diopters(p.focus_distance_m(zc, fc).value);
  };
  const Json &zs = j["zoom"];
  for (double fc = 0; fc <= 8000; fc += 50) {
    double max_slope = 0.0;
    for (std::size_t k = 0; k + 1 < zs.size(); ++k) {
      const double z0 = zs[k]["counts"].get<double>(), z1 = zs[k + 1]["counts"].get<double>();
      max_slope = std::max(max_slope, std::abs(d_at(z1, fc) - d_at(z0, fc)) / (z1 - z0));
    }
    double prev = d_at(-10, fc);
    for (double zc = -9; zc <= 3010; zc += 1.0) {
      const double d = d_at(zc, fc);
      EXPECT_LE(std::abs(d - prev), max_slope * (1 + 1e-9) + 1e-14)
          << "focus " << fc << " zoom " << zc;
      prev = d;
    }
    // And at each interior zoom point, from either side a millionth of a
    // count away.
    for (std::size_t k = 1; k + 1 < zs.size(); ++k) {
      const double z = zs[k]["counts"].get<double>();
      EXPECT_NEAR(d_at(z - 1e-6, fc), d_at(z, fc), 1e-6 * max_slope + 1e-14) << fc;
      EXPECT_NEAR(d_at(z + 1e-6, fc), d_at(z, fc), 1e-6 * max_slope + 1e-14) << fc;
    }
  }
}

TEST(PerZoomFocus, BlendIsLinearInZoomCountsAndKeepsInfinity) {
  const LensProfile p = LensProfile::load(kExample);
  // Zoom points at 900 (35 mm) and 1900 (50 mm); a quarter of the way.
  const double z = 1150, t = 0.25;
  for (const double fc : {150.0, 1700.0, 2600.0, 5000.0, 7000.0}) {
    const double a = diopters(p.focus_distance_m(900, fc).value);
    const double b = diopters(p.focus_distance_m(1900, fc).value);
    EXPECT_NEAR(diopters(p.focus_distance_m(z, fc).value), (1 - t) * a + t * b, 1e-14) << fc;
    EXPECT_NE(a, b) << "the tables differ at " << fc;
  }
  // The same focus counts are a different distance at each end of the zoom:
  // the point of per-zoom tables.
  EXPECT_NEAR(p.focus_distance_m(0, 4800).value, 1.5, 1e-12);
  EXPECT_LT(p.focus_distance_m(3000, 4800).value, 1.3);
  // At or past every table's infinity mark: infinity at any zoom, exactly.
  for (double zc = -50; zc <= 3050; zc += 0.5) {
    EXPECT_EQ(p.focus_distance_m(zc, 8000).value, kInf) << zc;
    EXPECT_EQ(p.focus_distance_m(zc, 9000).value, kInf) << zc;
  }
  // At infinity on one table only: finite, and far (7 m and infinity blend
  // towards infinity in diopters).
  const double half = p.focus_distance_m(2450, 7900).value; // 50 mm at inf, 70 mm short of it
  EXPECT_TRUE(std::isfinite(half));
  EXPECT_GT(half, 7.0);
  // The 24 mm table's infinity mark at 7600 is well short of it at 35 mm.
  EXPECT_EQ(p.focus_distance_m(0, 7600).value, kInf);
  EXPECT_TRUE(std::isfinite(p.focus_distance_m(900, 7600).value));
}

TEST(PerZoomFocus, ClampedWhereATableBlendedIsOutOfRangeOrZoomIs) {
  const LensProfile p = LensProfile::load(kExample);
  // Inside every table's counts at an interior zoom: not clamped.
  EXPECT_FALSE(p.focus_distance_m(1400, 4000).clamped);
  // Below the 50 mm table's close-focus mark (200), inside the 35 mm one's
  // (100): clamped between them, since the 50 mm part is its end value ...
  EXPECT_TRUE(p.focus_distance_m(1400, 150).clamped);
  // ... but not at the 35 mm point itself, where only its table counts.
  EXPECT_FALSE(p.focus_distance_m(900, 150).clamped);
  // Beyond the zoom table: the end table, flagged.
  const auto past = p.focus_distance_m(3500, 5300);
  EXPECT_TRUE(past.clamped);
  EXPECT_EQ(past.value, p.focus_distance_m(3000, 5300).value);
  EXPECT_TRUE(p.focus_distance_m(-1, 4800).clamped);
  EXPECT_EQ(p.focus_distance_m(-1, 4800).value, p.focus_distance_m(0, 4800).value);
  // Close-focus end: held at 0.38 m below every table.
  EXPECT_NEAR(p.focus_distance_m(2000, -10).value, 0.38, 1e-12);
  EXPECT_TRUE(p.focus_distance_m(2000, -10).clamped);
}

TEST(PerZoomFocus, EvaluateBlendsFocusAndBreathingAtTheZoom) {
  const LensProfile p = LensProfile::load(kExample);
  LensCounts c;
  c.focus = AxisReading{5150, 1000, true};
  c.zoom = AxisReading{1900, 900, true};
  LensState s = p.evaluate(c);
  EXPECT_NEAR(s.focus_distance_m.value, 1.5, 1e-12); // the 50 mm table's 1.5 m mark
  EXPECT_FALSE(s.focus_distance_m.clamped);
  // The focus distance depends on zoom too: the older time, fresh if both are.
  EXPECT_EQ(s.focus_distance_m.t_ns, 900);
  EXPECT_TRUE(s.focus_distance_m.fresh);
  // Breathing sees the blended distance: 1.5 m on the 50 mm point is 49.7 mm.
  EXPECT_NEAR(s.projection_focal_length_mm.value, 49.7, 1e-12);
  EXPECT_EQ(s.projection_focal_length_mm.value, p.projection_focal_length_mm(1900, 5150).value);
  c.zoom->fresh = false;
  EXPECT_FALSE(p.evaluate(c).focus_distance_m.fresh);

  // No focus reading: the far end at this zoom (infinity on every table
  // here), not clamped, not fresh; breathing at infinity.
  c.focus.reset();
  c.zoom = AxisReading{1400, 5, true};
  s = p.evaluate(c);
  EXPECT_EQ(s.focus_distance_m.value, kInf);
  EXPECT_FALSE(s.focus_distance_m.clamped);
  EXPECT_FALSE(s.focus_distance_m.fresh);
  EXPECT_NEAR(s.projection_focal_length_mm.value, s.focal_length_mm.value, 1e-12);
}

TEST(PerZoomFocus, RestFocusIsTheFarEndOfEachTableBlended) {
  // Tables whose far end is a finite distance (a lens whose scale stops short
  // of infinity): the rest focus at a zoom is the blend of their far ends.
  Json j = example();
  for (Json &z : j["zoom"])
    z["focus"].back()["distance_m"] = 100.0;
  j["zoom"][3]["focus"].back()["distance_m"] = 50.0;
  const LensProfile p = parse(j);
  LensCounts c;
  c.zoom = AxisReading{2450, 0, true}; // half-way from 50 to 70 mm
  const LensState s = p.evaluate(c);
  EXPECT_NEAR(1.0 / s.focus_distance_m.value, 0.5 * (1.0 / 100 + 1.0 / 50), 1e-15);
  EXPECT_FALSE(s.focus_distance_m.clamped);
}

TEST(PerZoomFocus, SameTableOnEveryZoomPointMatchesVersion1) {
  // A version 1 zoom and the version 2 profile with the v1 focus table copied
  // onto every zoom point: the same lens. At zoom points bit for bit; between
  // them the blend of two equal values, within rounding.
  Json v1 = example();
  v1["version"] = 1;
  v1["focus"] = v1["zoom"][1]["focus"];
  for (Json &z : v1["zoom"])
    z.erase("focus");
  Json v2 = example();
  for (Json &z : v2["zoom"])
    z["focus"] = v1["focus"];
  const LensProfile a = parse(v1), b = parse(v2);
  EXPECT_FALSE(a.has_per_zoom_focus());
  EXPECT_TRUE(b.has_per_zoom_focus());
  for (double zc = -100; zc <= 3100; zc += 50) {
    const bool at_point = zc <= 0 || zc == 900 || zc == 1900 || zc >= 3000;
    for (double fc = -50; fc <= 8050; fc += 7.5) {
      const auto x = a.focus_distance_m(zc, fc), y = b.focus_distance_m(zc, fc);
      if (at_point)
        EXPECT_EQ(x.value, y.value) << zc << " " << fc;
      else if (std::isinf(x.value))
        EXPECT_EQ(y.value, kInf);
      else
        EXPECT_NEAR(y.value, x.value, 1e-15 * x.value) << zc << " " << fc;
      EXPECT_EQ(x.clamped || (zc < 0 || zc > 3000), y.clamped) << zc << " " << fc;
      EXPECT_NEAR(a.projection_focal_length_mm(zc, fc).value,
                  b.projection_focal_length_mm(zc, fc).value, 1e-13);
    }
  }
}

} // namespace
} // namespace camhead::lens_control
