// camhead calibrate's fit: exact data come back as written; noisy,
// non-monotone data are pooled into a strictly monotone profile that loads;
// repeats average in diopters / stops / log f; malformed CSV lines name the
// file, line and column; too few points fail with the axis named.
#include <algorithm>
#include <cmath>
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
const char *kSource = "/virtual/marks.csv";
const std::string kHeader = "axis,counts,distance_m,f_number,t_stop,focal_length_mm\n";
const fs::path kLenses = fs::path(CAMHEAD_SOURCE_DIR) / "scenes" / "lenses";

std::string focus(int c, const std::string &d) {
  return "focus," + std::to_string(c) + "," + d + ",,,\n";
}
std::string iris(int c, const std::string &n, const std::string &t = "") {
  return "iris," + std::to_string(c) + ",," + n + "," + t + ",\n";
}
// Shortest text that reads back as exactly v.
std::string exact(double v) {
  return Json(v).dump();
}
std::string zoom(int c, const std::string &f) {
  return "zoom," + std::to_string(c) + ",,,," + f + "\n";
}

// Enough iris and zoom rows for a profile, when a test is about focus.
const std::string kIrisPrime = iris(0, "2") + iris(100, "4") + zoom(0, "35");

Calibration fit(const std::string &csv, bool prime = true) {
  return fit_calibration(parse_measurements(csv, kSource), {"test lens", "", prime});
}

// The fit's profile as the strict reader sees it.
LensProfile loaded(const Calibration &c, bool prime = true) {
  return LensProfile::parse(profile_json(c, {"test lens", "", prime}), "/virtual/fitted.json");
}

std::string error_of(const std::string &csv, bool prime = true) {
  try {
    (void)fit(csv, prime);
  } catch (const CalibrationError &e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Calibration, ExactPrimeDataReproducesTheExampleProfile) {
  // Every calibration point of the bundled example, measured once.
  std::ifstream in(kLenses / "example_35mm.json");
  const Json example = Json::parse(in);
  std::string csv = kHeader;
  for (const Json &p : example["focus"])
    csv +=
        focus(p["counts"].get<int>(), p["distance_m"].is_string() ? "inf" : p["distance_m"].dump());
  for (const Json &p : example["iris"])
    csv += iris(p["counts"].get<int>(), p["f_number"].dump(), p["t_stop"].dump());
  csv += zoom(0, "35");

  const MeasurementSet m = parse_measurements(csv, kSource);
  const Calibration c = fit_calibration(m, {"exact", "", true});
  ASSERT_EQ(c.focus.points.size(), example["focus"].size());
  ASSERT_EQ(c.iris.points.size(), example["iris"].size());
  for (std::size_t i = 0; i < c.focus.points.size(); ++i) {
    const Json &want = example["focus"][i]["distance_m"];
    EXPECT_EQ(c.focus.points[i].value, want.is_string() ? kInf : want.get<double>()) << i;
    EXPECT_EQ(c.focus.points[i].counts, example["focus"][i]["counts"].get<int>());
    EXPECT_EQ(c.focus.points[i].distinct_counts, 1u);
  }
  for (std::size_t i = 0; i < c.iris.points.size(); ++i) {
    EXPECT_EQ(c.iris.points[i].value, example["iris"][i]["f_number"].get<double>()) << i;
    EXPECT_EQ(*c.iris.points[i].t_stop, example["iris"][i]["t_stop"].get<double>()) << i;
  }
  const LensProfile p = loaded(c);
  EXPECT_FALSE(p.is_zoom());
  EXPECT_EQ(p.focal_length_mm(0).value, 35.0);
  const std::vector<Residuals> r = compute_residuals(m, p);
  ASSERT_EQ(r.size(), 5u); // diopters, metres, f-number, T-stop, focal length
  for (const Residuals &q : r)
    EXPECT_LE(q.max_abs, 1e-12) << q.quantity;
  EXPECT_NE(format_report(c, r).find("pooled by the monotone fit: none"), std::string::npos);
}

TEST(Calibration, ExactZoomDataReproducesItself) {
  const std::string csv = kHeader + focus(0, "inf") + focus(900, "0.5") + iris(0, "2.8") +
                          iris(50, "22") + zoom(0, "24") + zoom(500, "50") + zoom(900, "70");
  const Calibration c = fit(csv, false);
  ASSERT_EQ(c.zoom.points.size(), 3u);
  EXPECT_EQ(c.zoom.points[1].value, 50.0);
  const LensProfile p = loaded(c, false);
  EXPECT_TRUE(p.is_zoom());
  for (const Residuals &q : compute_residuals(parse_measurements(csv, kSource), p))
    EXPECT_LE(q.max_abs, 1e-12) << q.quantity;
}

TEST(Calibration, NoisyNonMonotoneDataArePooledIntoAProfileThatLoads) {
  // Diopters 3, 2, 2.2, 1, 0 over rising counts: the trend falls, 2 -> 2.2
  // is noise. Least-squares isotonic fit: those two pool to 2.1 D at their
  // mean counts.
  const std::string csv = kHeader + focus(0, "0.333333333333333333") + focus(1000, "0.5") +
                          focus(2000, exact(1.0 / 2.2)) + focus(3000, "1") + focus(4000, "inf") +
                          kIrisPrime;
  const Calibration c = fit(csv);
  ASSERT_EQ(c.focus.points.size(), 4u);
  const FittedPoint &pooled = c.focus.points[1];
  EXPECT_EQ(pooled.counts, 1500);
  EXPECT_EQ(pooled.first_counts, 1000);
  EXPECT_EQ(pooled.last_counts, 2000);
  EXPECT_EQ(pooled.distinct_counts, 2u);
  EXPECT_NEAR(1.0 / pooled.value, 2.1, 1e-12);
  EXPECT_EQ(c.focus.points[0].distinct_counts, 1u);

  const LensProfile p = loaded(c); // strictly monotone, or this throws
  EXPECT_NEAR(1.0 / p.focus_distance_m(1500).value, 2.1, 1e-12);
  // The residuals go through the profile's PCHIP: the pooled marks are
  // further off than the 0.1 D of the step fit, because the one point at
  // their centre is interpolated towards its neighbours at the marks; the
  // unpooled marks are exact.
  const MeasurementSet m = parse_measurements(csv, kSource);
  const std::vector<Residuals> r = compute_residuals(m, p);
  ASSERT_FALSE(r.empty());
  EXPECT_EQ(r[0].quantity, "focus, diopters");
  const double at1000 = 2.0 - 1.0 / p.focus_distance_m(1000).value;
  const double at2000 = 2.2 - 1.0 / p.focus_distance_m(2000).value;
  EXPECT_GT(std::abs(at1000), 0.1);
  EXPECT_NEAR(r[0].max_abs, std::max(std::abs(at1000), std::abs(at2000)), 1e-12);
  EXPECT_NEAR(r[0].rms, std::sqrt((at1000 * at1000 + at2000 * at2000) / 5), 1e-12);
  const std::string report = format_report(c, r);
  EXPECT_NE(report.find("focus: counts 1000..2000 (2 counts, 2 measurements) -> counts 1500"),
            std::string::npos)
      << report;
}

// Three marks at 20 m average to 1 ulp off 1/20 D, which ordered them
// against a lone 20 m mark at the next counts; both points were written as
// 20 m, and the profile reader refused the tie (found by
// tests/fuzz/calibration_fuzz). Points that would be written alike pool.
TEST(Calibration, PointsWrittenAlikePool) {
  ASSERT_NE((1.0 / 20 + 1.0 / 20 + 1.0 / 20) / 3, 1.0 / 20); // the rounding this is about
  const std::string csv = kHeader + focus(0, "0.3") + focus(13600, "20") + focus(13600, "20") +
                          focus(13600, "20") + focus(13601, "20") + focus(16384, "inf") +
                          kIrisPrime;
  const Calibration c = fit(csv);
  ASSERT_EQ(c.focus.points.size(), 3u);
  EXPECT_EQ(c.focus.points[1].first_counts, 13600);
  EXPECT_EQ(c.focus.points[1].last_counts, 13601);
  EXPECT_EQ(c.focus.points[1].value, 20.0); // all four said 20
  EXPECT_NO_THROW((void)loaded(c));
  // The fuzzer's own file, as `camhead calibrate --prime` reads it.
  const Calibration found =
      fit_calibration(read_measurements(fs::path(CAMHEAD_SOURCE_DIR) /
                                        "tests/assets/fuzz/calibration_tie_written_alike.csv"),
                      {"test lens", "", true});
  EXPECT_NO_THROW((void)loaded(found));
}

TEST(Calibration, PoolingFollowsTheTrendAndKeepsIrisChannelsTogether) {
  // Focus rising in diopters (infinity at low counts, as on many zooms) with
  // a tie at the close end; iris where only the T-stop runs backwards.
  const std::string csv = kHeader + focus(0, "inf") + focus(10, "2") + focus(20, "1") +
                          focus(30, "0.5") + focus(40, "0.5") + iris(0, "2", "2.2") +
                          iris(10, "2.8", "4.3") + iris(20, "4", "4.2") + iris(30, "5.6", "6") +
                          zoom(0, "50");
  const Calibration c = fit(csv);
  ASSERT_EQ(c.focus.points.size(), 4u);
  EXPECT_EQ(c.focus.points.back().value, 0.5); // the tie, written as measured
  EXPECT_EQ(c.focus.points.back().counts, 35);
  ASSERT_EQ(c.iris.points.size(), 3u);
  EXPECT_EQ(c.iris.points[1].counts, 15);
  EXPECT_NEAR(c.iris.points[1].value, std::sqrt(2.8 * 4.0), 1e-12); // mean in stops
  EXPECT_NEAR(*c.iris.points[1].t_stop, std::sqrt(4.3 * 4.2), 1e-12);
  const LensProfile p = loaded(c);
  EXPECT_TRUE(p.has_t_stop());
  EXPECT_GT(p.focus_distance_m(12).value, p.focus_distance_m(25).value);
}

TEST(Calibration, RepeatsAverageInTheLinearisingSpace) {
  // 1 m and infinity at one mark: 1 D and 0 D average to 0.5 D, i.e. 2 m.
  const std::string csv = kHeader + focus(100, "1") + focus(100, "inf") + focus(0, "0.25") +
                          iris(0, "2") + iris(0, "4") + iris(100, "8") + zoom(0, "24") +
                          zoom(0, "96") + zoom(100, "200");
  const Calibration c = fit(csv, false);
  ASSERT_EQ(c.focus.points.size(), 2u);
  EXPECT_EQ(c.focus.points[1].counts, 100);
  EXPECT_EQ(c.focus.points[1].measurements, 2u);
  EXPECT_NEAR(c.focus.points[1].value, 2.0, 1e-12);
  EXPECT_EQ(c.focus.distinct_counts, 2u);
  EXPECT_NEAR(c.iris.points[0].value, std::exp2(1.5), 1e-12); // f/2 and f/4: 3 stops, f/2.83
  EXPECT_NEAR(c.zoom.points[0].value, 48.0, 1e-12);           // 24 and 96 mm: geometric mean
  EXPECT_NEAR(loaded(c, false).focus_distance_m(100).value, 2.0, 1e-12);
}

TEST(Calibration, MalformedLinesNameFileLineAndColumn) {
  const std::string head = "# marks\n" + kHeader + "\n"; // the data start on line 4
  const struct {
    std::string text, want;
  } cases[] = {
      {head + "focus,0,abc,,,\n", "/virtual/marks.csv:4: distance_m: must be a number or inf"},
      {head + "focus,12.5,1,,,\n",
       ":4: counts: must be an integer within -2147483648 .. 2147483647"},
      {head + "focus,99999999999,1,,,\n", ":4: counts: must be an integer within -2147483648 .. "},
      {head + "focal,0,1,,,\n", ":4: axis: must be focus, iris or zoom"},
      {head + "focus,0,1,,\n", ":4: row: expected 6 fields as in the header, found 5"},
      {head + "focus,0,1,2.8,,\n", ":4: f_number: not used by focus rows"},
      {head + "focus,0,,,,\n", ":4: distance_m: missing"},
      {head + "focus,0,-1,,,\n", ":4: distance_m: must be within 0.001 .. 100000"},
      // 1/d would overflow: an internal invariant must not be what answers.
      {head + "focus,0,1e-310,,,\n", ":4: distance_m: must be within 0.001 .. 100000"},
      {head + "iris,0,,nan,,\n", ":4: f_number: must be a finite number"},
      {head + "iris,0,,200,,\n", ":4: f_number: must be within 0.5 .. 128"},
      {head + "iris,0,,2.8,2.5,\n", ":4: t_stop: must be >= f_number"},
      {head + "iris,0,,2.8,3,\niris,5,,4,,\n", ":5: t_stop: give t_stop on every iris row"},
      {head + "zoom,0,,,,inf\n", ":4: focal_length_mm: must be a finite number"},
      {"axis,counts,distance\n", "/virtual/marks.csv:1: distance: unknown column"},
      {"axis,counts,counts\n", ":1: counts: appears twice"},
      {"axis,distance_m\n", ":1: counts: missing from the header"},
      {"axis,counts,distance_m\niris,0,\n", ":2: f_number: missing from the header"},
      {"# nothing\n", "/virtual/marks.csv: header: missing (expected e.g. axis,counts,"},
  };
  for (const auto &c : cases) {
    const std::string got = error_of(c.text);
    EXPECT_NE(got.find(c.want), std::string::npos) << c.text << "gave: " << got;
  }
}

TEST(Calibration, CommentsBlankLinesAndWindowsLineEndsAreAccepted) {
  const std::string csv = "# lens A\r\n\r\n  axis , counts,distance_m,f_number,focal_length_mm\r\n"
                          "focus,0,0.3,,  # close focus\r\nfocus,10,INF,,\r\n"
                          "iris,0,,2,\r\niris,9,,4,\r\nzoom,0,,,35\r\n";
  const Calibration c = fit(csv);
  EXPECT_EQ(c.focus.points.back().value, kInf);
  EXPECT_EQ(c.focus.points.front().value, 0.3);
}

TEST(Calibration, TooFewPointsFailsClearly) {
  const struct {
    std::string text;
    bool prime;
    std::string want;
  } cases[] = {
      {kHeader + focus(5, "1") + focus(5, "2") + kIrisPrime, true,
       "/virtual/marks.csv: focus: 2 measurement(s), all at counts 5: a table needs 2 or more"},
      {kHeader + focus(0, "1") + focus(10, "1") + focus(20, "1") + kIrisPrime, true,
       "/virtual/marks.csv: focus: the monotone fit pools all 3 measurements into one point"},
      {kHeader + focus(0, "1") + focus(10, "2") + zoom(0, "35"), true,
       "/virtual/marks.csv: iris: no measurements"},
      {kHeader + focus(0, "1") + focus(10, "2") + iris(0, "2") + iris(10, "4"), true,
       "zoom: no measurements"},
      {kHeader + focus(0, "1") + focus(10, "2") + kIrisPrime, false,
       "(for a prime lens, pass "
       "--prime)"},
      {kHeader + focus(0, "1") + focus(10, "2") + kIrisPrime + zoom(10, "50"), true,
       "zoom: --prime needs every zoom row at the same counts"},
      {kHeader + focus(0, "1e5") + focus(0, "inf") + focus(10, "0.5") + kIrisPrime, true,
       "focus: the point at counts 0 averages to 200000 m, beyond the 1e5 m"},
  };
  for (const auto &c : cases) {
    const std::string got = error_of(c.text, c.prime);
    EXPECT_NE(got.find(c.want), std::string::npos) << c.text << "gave: " << got;
  }
}

TEST(Calibration, BundledExampleMeasurementsFitAndLoad) {
  const MeasurementSet m = read_measurements(kLenses / "example_35mm_measurements.csv");
  const CalibrationOptions options{"Example 35 mm T1.5", "", true};
  const Calibration c = fit_calibration(m, options);
  const LensProfile p = LensProfile::parse(profile_json(c, options), "/virtual/example.json");
  EXPECT_EQ(p.name(), "Example 35 mm T1.5");
  EXPECT_TRUE(p.has_t_stop());
  EXPECT_EQ(c.focus.points.size(), 8u); // 9 marks, the two noisy far ones pooled
  const std::vector<Residuals> r = compute_residuals(m, p);
  ASSERT_EQ(r.size(), 5u);
  EXPECT_LT(r[0].max_abs, 0.05);                  // diopters
  EXPECT_LT(r[2].max_abs, 0.05);                  // f-number stops
  EXPECT_EQ(r[4].max_abs, 0.0);                   // the prime's focal length
  std::printf("%s", format_report(c, r).c_str()); // for the README's example
}

TEST(Calibration, UnreadableFileIsAnError) {
  try {
    (void)read_measurements("/nonexistent/marks.csv");
    FAIL() << "no error";
  } catch (const CalibrationError &e) {
    EXPECT_STREQ(e.what(),
                 "/nonexistent/marks.csv: (file): cannot be opened: No such file or directory");
  }
}

} // namespace
} // namespace camhead::lens_control
