// camhead calibrate with per-zoom focus tables (a zoom_counts column on the
// focus rows): exact data reproduce the example zoom profile's tables; the
// bundled measurements fit, load as format version 2 and report residuals per
// zoom; zoom marks pooled by the monotone fit share their focus rows; each
// misuse names the file, line or table.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "camhead/lens_control/calibration.h"
#include "camhead/lens_control/lens_profile.h"

#include <gtest/gtest.h>

namespace camhead::lens_control {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr double kInf = std::numeric_limits<double>::infinity();
const char *kSource = "/virtual/zoom_marks.csv";
const std::string kHeader = "axis,counts,distance_m,f_number,t_stop,focal_length_mm,zoom_counts\n";
const fs::path kLenses = fs::path(CAMHEAD_SOURCE_DIR) / "scenes" / "lenses";

std::string focus(int c, const std::string &d, int zoom) {
  return "focus," + std::to_string(c) + "," + d + ",,,," + std::to_string(zoom) + "\n";
}
std::string iris(int c, const std::string &n) {
  return "iris," + std::to_string(c) + ",," + n + ",,,\n";
}
std::string zoom(int c, const std::string &f) {
  return "zoom," + std::to_string(c) + ",,,," + f + ",\n";
}

const std::string kIrisZoom = iris(0, "2.8") + iris(100, "8") + zoom(0, "24") + zoom(900, "70");

CalibrationOptions options(bool prime = false) {
  return {"test zoom", "", prime};
}

std::string error_of(const std::string &csv, bool prime = false) {
  try {
    (void)fit_calibration(parse_measurements(csv, kSource), options(prime));
  } catch (const CalibrationError &e) {
    return e.what();
  }
  return "(no error)";
}

TEST(CalibrationPerZoom, ExactDataReproduceTheExampleZoomProfile) {
  std::ifstream in(kLenses / "example_zoom_24_70.json");
  const Json example = Json::parse(in);
  std::string csv = kHeader;
  for (const Json &z : example["zoom"]) {
    for (const Json &p : z["focus"])
      csv += focus(p["counts"].get<int>(),
                   p["distance_m"].is_string() ? "inf" : p["distance_m"].dump(),
                   z["counts"].get<int>());
    csv += zoom(z["counts"].get<int>(), z["focal_length_mm"].dump());
  }
  for (const Json &p : example["iris"])
    csv += "iris," + p["counts"].dump() + ",," + p["f_number"].dump() + "," + p["t_stop"].dump() +
           ",,\n";

  const MeasurementSet m = parse_measurements(csv, kSource);
  const Calibration c = fit_calibration(m, options());
  ASSERT_EQ(c.zoom_focus.size(), 4u);
  EXPECT_TRUE(c.focus.points.empty());
  EXPECT_EQ(c.focus.measurements, 28u);
  const std::string json = profile_json(c, options());
  EXPECT_NE(json.find("\"version\": 2"), std::string::npos) << json;
  const LensProfile p = LensProfile::parse(json, "/virtual/fitted.json");
  EXPECT_TRUE(p.has_per_zoom_focus());
  for (const Json &z : example["zoom"])
    for (const Json &pt : z["focus"]) {
      const double want = pt["distance_m"].is_string() ? kInf : pt["distance_m"].get<double>();
      const double got =
          p.focus_distance_m(z["counts"].get<double>(), pt["counts"].get<double>()).value;
      if (std::isinf(want))
        EXPECT_EQ(got, want);
      else
        EXPECT_LE(std::abs(got - want), 1e-12 * want) << z["counts"] << " " << pt["counts"];
    }
  const std::vector<Residuals> r = compute_residuals(m, p);
  ASSERT_EQ(r.size(), 2u + 4u + 3u); // diopters, metres, 4 zooms, f-number, T-stop, focal length
  EXPECT_EQ(r[2].quantity, "focus @ zoom 0, diopters");
  EXPECT_EQ(r[5].quantity, "focus @ zoom 3000, diopters");
  EXPECT_EQ(r[5].count, 7u);
  for (const Residuals &q : r)
    EXPECT_LE(q.max_abs, 1e-12) << q.quantity;
  const std::string report = format_report(c, r);
  EXPECT_NE(report.find("(4 tables, one per zoom point)"), std::string::npos) << report;
  EXPECT_NE(report.find("  @ zoom 1900"), std::string::npos) << report;
}

TEST(CalibrationPerZoom, WithoutTheZoomCountsColumnTheProfileStaysVersion1) {
  const std::string csv = "axis,counts,distance_m,f_number,focal_length_mm\n"
                          "focus,0,inf,,\nfocus,900,0.5,,\niris,0,,2.8,\niris,50,,22,\n"
                          "zoom,0,,,24\nzoom,900,,,70\n";
  const Calibration c = fit_calibration(parse_measurements(csv, kSource), options());
  EXPECT_TRUE(c.zoom_focus.empty());
  const std::string json = profile_json(c, options());
  EXPECT_NE(json.find("\"version\": 1"), std::string::npos);
  EXPECT_FALSE(LensProfile::parse(json, "/virtual/v1.json").has_per_zoom_focus());
}

TEST(CalibrationPerZoom, BundledZoomMeasurementsFitAndLoad) {
  const MeasurementSet m = read_measurements(kLenses / "example_zoom_24_70_measurements.csv");
  const CalibrationOptions o{"Example 24-70 mm T2.9", "", false};
  const Calibration c = fit_calibration(m, o);
  const LensProfile p = LensProfile::parse(profile_json(c, o), "/virtual/example_zoom.json");
  EXPECT_TRUE(p.has_per_zoom_focus());
  ASSERT_EQ(c.zoom_focus.size(), 4u);
  EXPECT_EQ(c.zoom_focus[2].points.size(), 7u); // 8 marks, the two noisy far ones pooled
  const std::vector<Residuals> r = compute_residuals(m, p);
  ASSERT_EQ(r.size(), 9u);
  // Diopters, all zooms and per zoom: at most the spread of the repeats
  // (0.372 and 0.388 m at one close-focus mark are 0.11 D apart).
  EXPECT_LT(r[0].max_abs, 0.06);
  for (std::size_t i = 2; i < 6; ++i)
    EXPECT_LT(r[i].max_abs, 0.06) << r[i].quantity;
  EXPECT_LT(r[6].max_abs, 1e-12); // f-number, exact data
  EXPECT_EQ(r[8].max_abs, 0.0);   // focal lengths as measured
  const std::string report = format_report(c, r);
  EXPECT_NE(report.find("focus @ zoom 1900: counts 7450..7700 (2 counts, 2 measurements)"),
            std::string::npos)
      << report;
  std::printf("%s", report.c_str()); // for the README's example
}

TEST(CalibrationPerZoom, PooledZoomMarksShareTheirFocusRows) {
  // 24 mm at 0 and 23.9 mm at 10 (noise): the zoom fit pools them into one
  // point at counts 5, whose focus table takes the focus rows of both marks.
  const std::string csv = kHeader + focus(0, "0.5", 0) + focus(1000, "inf", 0) +
                          focus(500, "1", 10) + focus(0, "0.4", 900) + focus(1000, "inf", 900) +
                          iris(0, "2.8") + iris(100, "8") + zoom(0, "24") + zoom(10, "23.9") +
                          zoom(900, "70");
  const Calibration c = fit_calibration(parse_measurements(csv, kSource), options());
  ASSERT_EQ(c.zoom.points.size(), 2u);
  EXPECT_EQ(c.zoom.points[0].counts, 5);
  ASSERT_EQ(c.zoom_focus.size(), 2u);
  EXPECT_EQ(c.zoom_focus[0].measurements, 3u);
  EXPECT_EQ(c.zoom_focus[0].points.size(), 3u);
  const LensProfile p = LensProfile::parse(profile_json(c, options()), "/virtual/pooled.json");
  EXPECT_NEAR(p.focus_distance_m(5, 500).value, 1.0, 1e-12);
}

TEST(CalibrationPerZoom, MisuseNamesFileLineOrTable) {
  const struct {
    std::string text;
    bool prime;
    std::string want;
  } cases[] = {
      {kHeader + "iris,0,,2.8,,,0\n", false,
       "/virtual/zoom_marks.csv:2: zoom_counts: not used by iris rows"},
      {kHeader + "focus,0,1,,,,x\n", false, ":2: zoom_counts: must be an integer within"},
      {kHeader + focus(0, "1", 0) + "focus,10,2,,,,\n" + kIrisZoom, false,
       ":3: zoom_counts: give zoom_counts on every focus row or on none (line 2 has one)"},
      {kHeader + focus(0, "1", 0) + focus(10, "2", 0) + focus(0, "1", 500) + kIrisZoom, false,
       ":4: zoom_counts: no zoom row at counts 500"},
      {kHeader + focus(0, "1", 0) + focus(10, "2", 0) + kIrisZoom, false,
       "/virtual/zoom_marks.csv: focus at zoom counts 900: no focus measurements"},
      {kHeader + focus(0, "1", 0) + focus(0, "2", 0) + focus(0, "1", 900) + focus(10, "2", 900) +
           kIrisZoom,
       false, "focus at zoom counts 0: 2 measurement(s), all at counts 0"},
      {kHeader + focus(0, "1", 0) + focus(10, "2", 0) + focus(0, "2", 900) + focus(10, "1", 900) +
           kIrisZoom,
       false,
       "focus at zoom counts 900: the fitted distances fall as counts rise, the other way from "
       "the table at zoom counts 0"},
      {kHeader + focus(0, "1", 0) + focus(10, "2", 0) + iris(0, "2.8") + iris(100, "8") +
           zoom(0, "35"),
       true, "/virtual/zoom_marks.csv: focus: the zoom_counts column gives per-zoom focus tables"},
  };
  for (const auto &c : cases) {
    const std::string got = error_of(c.text, c.prime);
    EXPECT_NE(got.find(c.want), std::string::npos) << c.text << "gave: " << got;
  }
}

} // namespace
} // namespace camhead::lens_control
