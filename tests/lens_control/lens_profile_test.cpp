// Lens profiles: the bundled example loads; every calibration point comes
// back exactly; values between points are monotone; infinity and the close
// focus limit; zoom blending of focus breathing; the uncalibrated fallback.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "camhead/lens_control/lens_profile.h"

#include <gtest/gtest.h>

namespace camhead::lens_control {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kExample = fs::path(CAMHEAD_SOURCE_DIR) / "scenes" / "lenses" / "example_35mm.json";
constexpr double kInf = std::numeric_limits<double>::infinity();

Json read_json(const fs::path &p) {
  std::ifstream in(p);
  return Json::parse(in);
}

// Exact, or within 1e-12 relative where the value goes through its
// linearising space and back (1/(1/d), 2^(log2 N)).
void expect_reproduced(double got, double want, const std::string &what) {
  if (std::isinf(want))
    EXPECT_EQ(got, want) << what;
  else
    EXPECT_LE(std::abs(got - want), 1e-12 * std::abs(want))
        << what << ": " << got << " vs " << want;
}

// A 24-70 zoom whose focus encoder runs from infinity (low counts) to close
// focus (high counts), the other way round from the example prime.
Json zoom_lens() {
  return Json::parse(R"({
    "format": "camhead-lens-profile", "version": 1, "name": "test zoom",
    "focus": [{"counts": 100, "distance_m": "infinity"}, {"counts": 900, "distance_m": 3},
              {"counts": 2500, "distance_m": 1}, {"counts": 5000, "distance_m": 0.45}],
    "iris": [{"counts": -300, "f_number": 22}, {"counts": 0, "f_number": 8},
             {"counts": 700, "f_number": 2.8}],
    "zoom": [
      {"counts": 0, "focal_length_mm": 24, "entrance_pupil_offset_mm": 95,
       "projection_focal_length_mm": [{"distance_m": "infinity", "projection_focal_length_mm": 24},
                                      {"distance_m": 0.45, "projection_focal_length_mm": 23.1}]},
      {"counts": 1000, "focal_length_mm": 35, "entrance_pupil_offset_mm": 80,
       "projection_focal_length_mm": 35.2},
      {"counts": 2500, "focal_length_mm": 50, "entrance_pupil_offset_mm": 70,
       "projection_focal_length_mm": [{"distance_m": 0.45, "projection_focal_length_mm": 53},
                                      {"distance_m": 2, "projection_focal_length_mm": 50.6},
                                      {"distance_m": "infinity", "projection_focal_length_mm": 50}]},
      {"counts": 4000, "focal_length_mm": 70, "entrance_pupil_offset_mm": 88,
       "projection_focal_length_mm": 71}
    ]})");
}

LensProfile parse(const Json &j) {
  return LensProfile::parse(j.dump(), "/virtual/lens.json");
}

TEST(LensProfile, ExampleLoadsAndReproducesEveryCalibrationPoint) {
  const LensProfile p = LensProfile::load(kExample);
  const Json j = read_json(kExample);
  EXPECT_TRUE(p.calibrated());
  EXPECT_FALSE(p.is_zoom());
  EXPECT_TRUE(p.has_t_stop());
  for (const auto &pt : j["focus"]) {
    const double c = pt["counts"].get<double>();
    const double want = pt["distance_m"].is_string() ? kInf : pt["distance_m"].get<double>();
    expect_reproduced(p.focus_distance_m(c).value, want, "focus at " + std::to_string(c));
    EXPECT_FALSE(p.focus_distance_m(c).clamped);
  }
  for (const auto &pt : j["iris"]) {
    const double c = pt["counts"].get<double>();
    expect_reproduced(p.f_number(c).value, pt["f_number"].get<double>(), "iris");
    expect_reproduced(p.t_stop(c)->value, pt["t_stop"].get<double>(), "t_stop");
  }
  // Breathing points, addressed through the focus counts of the same distance.
  expect_reproduced(p.projection_focal_length_mm(0, 0).value, 38.9, "breathing at 0.3 m");
  expect_reproduced(p.projection_focal_length_mm(0, 4300).value, 36.9, "breathing at 0.6 m");
  expect_reproduced(p.projection_focal_length_mm(0, 9400).value, 35.6, "breathing at 2 m");
  expect_reproduced(p.projection_focal_length_mm(0, 16383).value, 35.0, "breathing at inf");
  EXPECT_EQ(p.focal_length_mm(123).value, 35.0);
  EXPECT_EQ(p.entrance_pupil_offset_mm(123).value, 68.0);
  // No distortion in the example (the simulated rig films through it); a
  // version 1 distortion reads as given.
  EXPECT_FALSE(p.distortion());
  Json with = j;
  with["distortion"] = {{"k1", -0.042}, {"p2", 0.001}};
  const LensProfile distorted = LensProfile::parse(with.dump(), kExample);
  ASSERT_TRUE(distorted.distortion());
  EXPECT_EQ(distorted.distortion()->k1, -0.042);
  EXPECT_EQ(distorted.distortion()->p2, 0.001);
  EXPECT_EQ(distorted.distortion()->k2, 0.0);
}

TEST(LensProfile, MonotoneBetweenCalibrationPointsOnDenseSweep) {
  const LensProfile p = LensProfile::load(kExample);
  double prev_d = 0.0, prev_n = 0.0, prev_t = 0.0, prev_proj = kInf;
  for (int c = 0; c <= 16383; ++c) {
    const double d = p.focus_distance_m(c).value;
    EXPECT_GT(d, prev_d) << "focus at " << c; // strictly: PCHIP of strictly monotone data
    prev_d = d;
    const double proj = p.projection_focal_length_mm(0, c).value;
    EXPECT_LE(proj, prev_proj) << "breathing at " << c;
    prev_proj = proj;
  }
  for (int c = 0; c <= 4095; ++c) {
    const double n = p.f_number(c).value, t = p.t_stop(c)->value;
    EXPECT_GT(n, prev_n) << "iris at " << c;
    EXPECT_GT(t, prev_t) << "t-stop at " << c;
    EXPECT_GE(t, n * (1 - 1e-12)) << "t-stop below f-number at " << c;
    prev_n = n;
    prev_t = t;
  }
}

TEST(LensProfile, InfinityAndCloseFocusLimits) {
  const LensProfile p = LensProfile::load(kExample);
  EXPECT_EQ(p.focus_distance_m(16383).value, kInf);
  // Just short of the infinity mark: finite, far, and beyond the 20 m mark.
  const double near_inf = p.focus_distance_m(16382).value;
  EXPECT_TRUE(std::isfinite(near_inf));
  EXPECT_GT(near_inf, 1000.0);
  // Past the infinity mark (a ring with travel beyond it): clamped to infinity.
  EXPECT_EQ(p.focus_distance_m(17000).value, kInf);
  EXPECT_TRUE(p.focus_distance_m(17000).clamped);
  // Below the close-focus mark: held at close focus, flagged.
  EXPECT_EQ(p.focus_distance_m(-50).value, 0.3);
  EXPECT_TRUE(p.focus_distance_m(-50).clamped);
  EXPECT_TRUE(p.f_number(5000).clamped);
  EXPECT_EQ(p.f_number(5000).value, p.f_number(4095).value);
}

TEST(LensProfile, ZoomLensReversedFocusAndBreathingBlend) {
  const Json j = zoom_lens();
  const LensProfile p = parse(j);
  EXPECT_TRUE(p.is_zoom());
  EXPECT_FALSE(p.has_t_stop());
  EXPECT_FALSE(p.t_stop(0));
  // Focus falls with counts here.
  EXPECT_EQ(p.focus_distance_m(100).value, kInf);
  expect_reproduced(p.focus_distance_m(5000).value, 0.45, "close focus");
  double prev = kInf;
  for (int c = 101; c <= 5000; ++c) {
    EXPECT_LT(p.focus_distance_m(c).value, prev) << c;
    prev = p.focus_distance_m(c).value;
  }
  // Iris with negative counts and a falling f-number.
  expect_reproduced(p.f_number(-300).value, 22, "iris");
  expect_reproduced(p.f_number(700).value, 2.8, "iris");
  // Zoom points exactly, focal length monotone between them.
  for (const auto &z : j["zoom"]) {
    const double c = z["counts"].get<double>();
    EXPECT_EQ(p.focal_length_mm(c).value, z["focal_length_mm"].get<double>());
    EXPECT_EQ(p.entrance_pupil_offset_mm(c).value, z["entrance_pupil_offset_mm"].get<double>());
  }
  double prev_f = 0;
  for (int c = 0; c <= 4000; ++c) {
    EXPECT_GT(p.focal_length_mm(c).value, prev_f) << c;
    prev_f = p.focal_length_mm(c).value;
  }
  // Breathing at zoom points, per focus, exactly.
  expect_reproduced(p.projection_focal_length_mm(0, 5000).value, 23.1, "24 mm close");
  expect_reproduced(p.projection_focal_length_mm(0, 100).value, 24, "24 mm inf");
  expect_reproduced(p.projection_focal_length_mm(1000, 2500).value, 35.2, "35 mm constant");
  expect_reproduced(p.projection_focal_length_mm(2500, 5000).value, 53, "50 mm close");
  expect_reproduced(p.projection_focal_length_mm(2500, 100).value, 50, "50 mm inf");
  // Half-way between the 35 and 50 mm points at infinity: the focal length
  // times the mean of the two ratios (35.2/35 and 50/50).
  const double f = p.focal_length_mm(1750).value;
  EXPECT_NEAR(p.projection_focal_length_mm(1750, 100).value, f * 0.5 * (35.2 / 35 + 1.0), 1e-12);
  EXPECT_GT(f, 35);
  EXPECT_LT(f, 50);
  // Outside the zoom table: clamped and flagged.
  EXPECT_EQ(p.focal_length_mm(9000).value, 70);
  EXPECT_TRUE(p.focal_length_mm(9000).clamped);
  EXPECT_TRUE(p.projection_focal_length_mm(9000, 100).clamped);
}

TEST(LensProfile, Version1LookupsAreBitIdenticalToBeforePerZoomFocus) {
  // Values printed (%a) by the lookups as they were before per-zoom focus
  // tables (format version 2) were added: a version 1 profile must not move
  // by a single bit. Only lookups made of + - * / (no exp or log), so that the
  // figures do not depend on the C library's rounding.
  const LensProfile p = LensProfile::load(kExample);
  const struct {
    double counts, distance, projection;
    bool clamped;
  } prime[] = {
      {-50, 0x1.3333333333333p-2, 0x1.3733333333333p+5, true},
      {1234.5, 0x1.68790e1b9869ap-2, 0x1.326eac3c5e53p+5, false},
      {7777, 0x1.3d838ce309586p+0, 0x1.1f930a7255952p+5, false},
      {13600.25, 0x1.400cb1b7d0a03p+4, 0x1.187b37b5008cp+5, false},
      {16382, 0x1.b2f4fddb51249p+15, 0x1.18000b4ce9abcp+5, false},
      {17000, kInf, 0x1.18p+5, true},
  };
  for (const auto &c : prime) {
    EXPECT_EQ(p.focus_distance_m(c.counts).value, c.distance) << c.counts;
    EXPECT_EQ(p.focus_distance_m(c.counts).clamped, c.clamped) << c.counts;
    EXPECT_EQ(p.projection_focal_length_mm(0, c.counts).value, c.projection) << c.counts;
  }
  const LensProfile z = parse(zoom_lens());
  EXPECT_EQ(z.focus_distance_m(640.5).value, 0x1.1c2e6a9167f68p+2);
  EXPECT_EQ(z.focus_distance_m(4321).value, 0x1.0faa1531b31fep-1);
  EXPECT_EQ(z.focus_distance_m(6000).value, 0x1.cccccccccccccp-2);
  // Whatever the zoom: one focus table.
  EXPECT_EQ(z.focus_distance_m(1750, 4321).value, 0x1.0faa1531b31fep-1);
  EXPECT_FALSE(z.focus_distance_m(9000, 4321).clamped);
  EXPECT_EQ(z.projection_focal_length_mm(0, 640.5).value, 0x1.7e8a6809d4951p+4);
  EXPECT_EQ(z.projection_focal_length_mm(2500, 4321).value, 0x1.a42f6dfdb7521p+5);
  EXPECT_FALSE(z.has_per_zoom_focus());
}

TEST(LensProfile, EvaluateCarriesTimestampsFreshnessAndRestValues) {
  const LensProfile p = parse(zoom_lens());
  LensCounts c;
  c.focus = AxisReading{2500, 1000, true};
  c.zoom = AxisReading{2500, 900, false};
  const LensState s = p.evaluate(c);
  EXPECT_TRUE(s.calibrated);
  expect_reproduced(s.focus_distance_m.value, 1.0, "focus");
  EXPECT_EQ(s.focus_distance_m.t_ns, 1000);
  EXPECT_TRUE(s.focus_distance_m.fresh);
  EXPECT_EQ(s.focal_length_mm.value, 50);
  EXPECT_FALSE(s.focal_length_mm.fresh);
  // Depends on both: the older time, fresh only if both are.
  EXPECT_EQ(s.projection_focal_length_mm.t_ns, 900);
  EXPECT_FALSE(s.projection_focal_length_mm.fresh);
  // No iris reading: wide open, not fresh.
  expect_reproduced(s.f_number.value, 2.8, "rest iris");
  EXPECT_FALSE(s.f_number.fresh);
  EXPECT_FALSE(s.all_fresh());
  EXPECT_FALSE(s.distortion);
  // Field of view follows the projection focal length (breathing included).
  EXPECT_NEAR(field_of_view_rad(s, 36.0), 2 * std::atan(18.0 / s.projection_focal_length_mm.value),
              1e-15);
}

TEST(LensProfile, UncalibratedFallbackIsFlaggedAndNominal) {
  const LensProfile p = LensProfile::uncalibrated();
  EXPECT_FALSE(p.calibrated());
  EXPECT_NE(p.name().find("uncalibrated"), std::string::npos);
  LensCounts c;
  c.focus = AxisReading{12345, 7, true};
  c.iris = AxisReading{-99, 7, true};
  const LensState s = p.evaluate(c);
  EXPECT_FALSE(s.calibrated);
  EXPECT_EQ(s.focus_distance_m.value, kInf);
  EXPECT_FALSE(s.focus_distance_m.clamped);
  EXPECT_NEAR(s.f_number.value, 2.8, 1e-12);
  EXPECT_EQ(s.focal_length_mm.value, 35);
  EXPECT_EQ(s.projection_focal_length_mm.value, 35);
  EXPECT_TRUE(s.focus_distance_m.fresh); // the encoder is live; the map is what is nominal
}

} // namespace
} // namespace camhead::lens_control
