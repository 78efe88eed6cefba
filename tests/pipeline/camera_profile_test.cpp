// Where `camhead calibrate camera` writes a camera point (tracking/
// camera_profile.h): into the zoom point and focus the views were taken at,
// replacing one at the same distance, and never into a profile it would
// leave unreadable or wrong, each refusal naming the option or field.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "camhead/lens_control/lens_profile.h"
#include "tracking/camera_profile.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;
const fs::path kLenses = fs::path(CAMHEAD_SOURCE_DIR) / "scenes" / "lenses";

std::string text_of(const fs::path &p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

CameraModel camera(double k1) {
  CameraModel c;
  c.fx = c.fy = 1900.0;
  c.cx = 959.5;
  c.cy = 539.5;
  c.distortion = {k1, 0.0, 0.0, 0.0, 0.0};
  return c;
}

std::string error_of(const std::string &profile, const CameraPointPlace &place) {
  try {
    (void)profile_with_camera(profile, "lens.json", place, camera(-0.1));
  } catch (const CameraProfileError &e) {
    return e.what();
  }
  return "written";
}

TEST(CameraProfile, APrimeGetsItsPointsAndAPointAtTheSameFocusIsReplaced) {
  const std::string v1 = text_of(kLenses / "example_35mm.json");
  CameraPointPlace place;
  place.focus_counts = 9400; // 2 m
  place.sensor_width_mm = 36.0;
  place.width_px = 1920;
  place.height_px = 1080;
  std::string v3 = profile_with_camera(v1, "lens.json", place, camera(-0.1));
  place.sensor_width_mm.reset(); // the profile has it now
  place.focus_counts = 16383;    // infinity
  v3 = profile_with_camera(v3, "lens.json", place, camera(-0.05));
  place.focus_counts = 9400;
  v3 = profile_with_camera(v3, "lens.json", place, camera(-0.12)); // replaces the first
  const auto j = nlohmann::json::parse(v3);
  EXPECT_EQ(j["version"], 3);
  EXPECT_FALSE(j["prime"].contains("projection_focal_length_mm"));
  ASSERT_EQ(j["prime"]["camera"].size(), 2u);
  EXPECT_EQ(j["prime"]["camera"][0]["k1"], -0.12); // near first
  EXPECT_EQ(j["prime"]["camera"][1]["distance_m"], "infinity");
  const lens_control::LensProfile p = lens_control::LensProfile::parse(v3, "lens.json");
  lens_control::LensCounts counts;
  counts.focus = lens_control::AxisReading{9400.0, 0, true};
  EXPECT_DOUBLE_EQ(p.evaluate(counts).distortion->k1, -0.12);
}

TEST(CameraProfile, WhatCannotBeWrittenIsRefusedByName) {
  const std::string prime = text_of(kLenses / "example_35mm.json");
  const std::string zoom = text_of(kLenses / "example_zoom_24_70.json");
  CameraPointPlace place;
  place.focus_counts = 9400;
  place.width_px = 1920;
  place.height_px = 1080;
  EXPECT_EQ(error_of(prime, place).rfind("--sensor-width-mm: lens.json has no camera model", 0), 0u)
      << error_of(prime, place);
  place.sensor_width_mm = 36.0;
  place.zoom_counts = 0.0;
  EXPECT_EQ(error_of(prime, place).rfind("--at zoom=0: lens.json is a prime", 0), 0u)
      << error_of(prime, place);
  EXPECT_NE(error_of(zoom, place)
                .find("a zoom lens's profile gets a camera model on every zoom "
                      "point at once"),
            std::string::npos)
      << error_of(zoom, place);
  place.zoom_counts = 123.0;
  EXPECT_EQ(error_of(zoom, place).rfind("--at zoom=123: lens.json has no zoom point", 0), 0u)
      << error_of(zoom, place);
  place.zoom_counts.reset();
  place.focus_counts = 99999;
  EXPECT_EQ(error_of(prime, place).rfind("--at focus=99999: outside the focus table", 0), 0u)
      << error_of(prime, place);
  // Once version 3, the image is the views' for good.
  place.focus_counts = 9400;
  const std::string v3 = profile_with_camera(prime, "lens.json", place, camera(-0.1));
  place.width_px = 1280;
  place.height_px = 720;
  EXPECT_EQ(error_of(v3, place).rfind("the views are 1280x720, but lens.json's camera model is "
                                      "in 1920x1080 pixels",
                                      0),
            0u)
      << error_of(v3, place);
}

} // namespace
} // namespace camhead::pipeline
