// Lens profiles of format version 3: OpenCV's camera model (fx fy cx cy, k1
// k2 p1 p2 k3) per zoom point over focus, in the pixels of the profile's
// image. Its points come back exactly; between them it is interpolated in
// diopters and blended across zoom as breathing is; fx is the projection
// focal length; and what is wrong is refused with the field named.
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "camhead/lens_control/lens_profile.h"

#include <gtest/gtest.h>

namespace camhead::lens_control {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kExample = fs::path(CAMHEAD_SOURCE_DIR) / "scenes" / "lenses" / "example_35mm.json";

// The example prime made version 3: a 1920x1080 image on a 36 mm sensor
// (fx 1866.7 px at 35 mm), its camera calibrated at 0.5 m and at infinity.
Json prime_v3() {
  std::ifstream in(kExample);
  Json j = Json::parse(in);
  j["version"] = 3;
  j.erase("distortion");
  j["image"] = {{"width_px", 1920}, {"height_px", 1080}, {"sensor_width_mm", 36.0}};
  j["prime"].erase("projection_focal_length_mm");
  j["prime"]["camera"] = Json::parse(R"([
    {"distance_m": 0.5, "fx": 1950.0, "fy": 1952.0, "cx": 963.5, "cy": 537.25,
     "k1": -0.08, "k2": 0.02, "p1": 0.001, "p2": -0.0005, "k3": 0.004},
    {"distance_m": "infinity", "fx": 1866.0, "fy": 1867.9, "cx": 961.0, "cy": 540.5,
     "k1": -0.05, "k2": 0.01}])");
  return j;
}

LensProfile parse(const Json &j) {
  return LensProfile::parse(j.dump(), "/virtual/lens.json");
}

std::string error_of(const Json &j) {
  try {
    (void)parse(j);
  } catch (const ProfileError &e) {
    return e.what();
  }
  return "read";
}

LensState at_focus(const LensProfile &p, double metres) {
  LensValues values;
  values.focus_diopters = AxisReading{std::isinf(metres) ? 0.0 : 1.0 / metres, 0, true};
  return p.evaluate({}, values);
}

TEST(CameraModelProfile, ItsPointsComeBackExactly) {
  const LensProfile p = parse(prime_v3());
  ASSERT_TRUE(p.has_camera_model());
  const LensState near = at_focus(p, 0.5);
  EXPECT_DOUBLE_EQ(near.projection_focal_length_mm.value, 1950.0 * 36.0 / 1920.0);
  EXPECT_DOUBLE_EQ(near.projection.principal_x, (963.5 + 0.5) / 1920.0);
  EXPECT_DOUBLE_EQ(near.projection.principal_y, (537.25 + 0.5) / 1080.0);
  EXPECT_DOUBLE_EQ(near.projection.fy_over_fx, 1952.0 / 1950.0);
  ASSERT_TRUE(near.distortion);
  EXPECT_DOUBLE_EQ(near.distortion->k1, -0.08);
  EXPECT_DOUBLE_EQ(near.distortion->k2, 0.02);
  EXPECT_DOUBLE_EQ(near.distortion->p1, 0.001);
  EXPECT_DOUBLE_EQ(near.distortion->p2, -0.0005);
  EXPECT_DOUBLE_EQ(near.distortion->k3, 0.004);
  const LensState far = at_focus(p, INFINITY);
  EXPECT_DOUBLE_EQ(far.projection_focal_length_mm.value, 1866.0 * 36.0 / 1920.0);
  EXPECT_DOUBLE_EQ(far.distortion->k1, -0.05);
  EXPECT_DOUBLE_EQ(far.distortion->k3, 0.0); // not given: none
}

// Between its points each parameter stays within theirs (PCHIP in
// diopters): the image scale breathes smoothly through a pull.
TEST(CameraModelProfile, BetweenItsPointsEachParameterStaysBetweenTheirs) {
  const LensProfile p = parse(prime_v3());
  double last_mm = INFINITY;
  for (const double metres : {0.55, 0.7, 1.0, 2.0, 5.0, 50.0}) {
    const LensState s = at_focus(p, metres);
    EXPECT_GT(s.distortion->k1, -0.08);
    EXPECT_LT(s.distortion->k1, -0.05);
    EXPECT_LT(s.projection_focal_length_mm.value, last_mm) << metres; // falls towards infinity
    last_mm = s.projection_focal_length_mm.value;
  }
}

// A zoom's camera tables, one point each, blend linearly in zoom counts
// between the zoom points.
TEST(CameraModelProfile, AZoomBlendsItsPointsCameras) {
  Json j = prime_v3();
  const Json camera = j["prime"]["camera"];
  j.erase("prime");
  j["zoom"] = Json::array();
  j["zoom"].push_back({{"counts", 0}, {"focal_length_mm", 24.0}, {"camera", {camera[1]}}});
  Json tele = camera[1];
  tele["fx"] = 3700.0;
  tele["fy"] = 3700.0;
  tele["cx"] = 955.0;
  tele["k1"] = 0.03;
  j["zoom"].push_back({{"counts", 1000}, {"focal_length_mm", 70.0}, {"camera", {tele}}});
  const LensProfile p = parse(j);
  LensCounts counts;
  counts.zoom = AxisReading{250.0, 0, true};
  const LensState s = p.evaluate(counts);
  EXPECT_NEAR(s.distortion->k1, 0.75 * -0.05 + 0.25 * 0.03, 1e-15);
  EXPECT_NEAR(s.projection.principal_x, (0.75 * 961.0 + 0.25 * 955.0 + 0.5) / 1920.0, 1e-15);
}

TEST(CameraModelProfile, WhatIsWrongIsRefusedByName) {
  struct Case {
    const char *what;
    void (*change)(Json &);
    const char *expected; // the message's start after the file
  };
  const Case cases[] = {
      {"no image", [](Json &j) { j.erase("image"); }, "image: missing"},
      {"a camera on version 1",
       [](Json &j) {
         j["version"] = 1;
         j.erase("image");
       },
       "prime.camera: a camera model needs \"version\": 3"},
      {"an image on version 1",
       [](Json &j) {
         j["version"] = 1;
         j["prime"].erase("camera");
       },
       "image: belongs to a camera model"},
      {"no camera on version 3", [](Json &j) { j["prime"].erase("camera"); },
       "prime.camera: missing"},
      {"an empty camera table", [](Json &j) { j["prime"]["camera"] = Json::array(); },
       "prime.camera: needs at least 1 camera point"},
      {"breathing beside it", [](Json &j) { j["prime"]["projection_focal_length_mm"] = 35.0; },
       "prime.projection_focal_length_mm: a camera model's fx sets the image scale"},
      {"top-level distortion",
       [](Json &j) {
         j["distortion"] = {{"k1", 0.1}};
       },
       "distortion: a version 3 profile gives the distortion with each camera point"},
      {"the principal point outside the image",
       [](Json &j) { j["prime"]["camera"][0]["cx"] = 1920.0; }, "prime.camera[0].cx:"},
      {"a focal length of nothing", [](Json &j) { j["prime"]["camera"][1]["fy"] = 0.0; },
       "prime.camera[1].fy:"},
      {"a distance twice", [](Json &j) { j["prime"]["camera"][1]["distance_m"] = 0.5; },
       "prime.camera[1].distance_m: not strictly monotone"},
      {"an unknown coefficient", [](Json &j) { j["prime"]["camera"][0]["k4"] = 0.0; },
       "prime.camera[0].k4:"},
      {"a version 4", [](Json &j) { j["version"] = 4; },
       "version: unsupported version (this reader understands 1, 2 and 3)"},
  };
  for (const Case &c : cases) {
    Json j = prime_v3();
    c.change(j);
    const std::string error = error_of(j);
    EXPECT_EQ(error.rfind(std::string("/virtual/lens.json: ") + c.expected, 0), 0u)
        << c.what << ": " << error;
  }
}

} // namespace
} // namespace camhead::lens_control
