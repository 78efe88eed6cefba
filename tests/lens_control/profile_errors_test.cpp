// Malformed profiles: one variant per validation rule, each of which must fail
// with ProfileError naming the file and the offending field; then syntax
// errors and damaged text, which must never yield anything but a profile or a
// ProfileError.
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "camhead/lens_control/lens_profile.h"

#include <gtest/gtest.h>

namespace camhead::lens_control {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kExample = fs::path(CAMHEAD_SOURCE_DIR) / "scenes" / "lenses" / "example_35mm.json";
const char *kSource = "/virtual/bad_lens.json";

Json example() {
  std::ifstream in(kExample);
  return Json::parse(in);
}

// A minimal zoom profile, for the zoom rules.
Json zoom_base() {
  Json j = example();
  j.erase("prime");
  j["zoom"] = Json::parse(R"([
    {"counts": 0, "focal_length_mm": 24, "entrance_pupil_offset_mm": 90},
    {"counts": 500, "focal_length_mm": 50, "entrance_pupil_offset_mm": 70},
    {"counts": 900, "focal_length_mm": 70, "entrance_pupil_offset_mm": 80}])");
  return j;
}

// The same zoom with a focus table per zoom point (format version 2), each
// the example's table shifted by 100 counts per zoom point.
Json per_zoom_base() {
  Json j = zoom_base();
  j["version"] = 2;
  for (std::size_t i = 0; i < j["zoom"].size(); ++i) {
    j["zoom"][i]["focus"] = j["focus"];
    for (Json &pt : j["zoom"][i]["focus"])
      pt["counts"] = pt["counts"].get<int>() + 100 * int(i);
  }
  j.erase("focus");
  return j;
}

enum class Base { prime, zoom, per_zoom };

struct BadCase {
  const char *what;
  std::function<void(Json &)> edit;
  const char *field;
  Base base = Base::prime;
};

const std::vector<BadCase> kCases = {
    // Header.
    {"missing format", [](Json &j) { j.erase("format"); }, "format"},
    {"wrong format", [](Json &j) { j["format"] = "camhead-scene"; }, "format"},
    {"format not a string", [](Json &j) { j["format"] = 1; }, "format"},
    {"version 2 with a top-level focus", [](Json &j) { j["version"] = 2; }, "version"},
    {"version 4", [](Json &j) { j["version"] = 4; }, "version"},
    {"version 3 without a camera model", [](Json &j) { j["version"] = 3; }, "image"},
    {"version as string", [](Json &j) { j["version"] = "1"; }, "version"},
    {"version as float", [](Json &j) { j["version"] = 1.0; }, "version"},
    {"empty name", [](Json &j) { j["name"] = ""; }, "name"},
    {"name not a string", [](Json &j) { j["name"] = Json::array(); }, "name"},
    {"description not a string", [](Json &j) { j["description"] = 3; }, "description"},
    {"unknown top-level field", [](Json &j) { j["focsu"] = 1; }, "focsu"},
    {"both zoom and prime", [](Json &j) { j["zoom"] = zoom_base()["zoom"]; }, "prime"},
    {"neither zoom nor prime", [](Json &j) { j.erase("prime"); }, "zoom"},
    {"root is an array", [](Json &j) { j = Json::array(); }, "(top level)"},
    // Focus table.
    {"focus missing", [](Json &j) { j.erase("focus"); }, "focus"},
    {"focus not an array", [](Json &j) { j["focus"] = Json::object(); }, "focus"},
    {"focus with one point", [](Json &j) { j["focus"] = Json::array({j["focus"][0]}); }, "focus"},
    {"focus empty", [](Json &j) { j["focus"] = Json::array(); }, "focus"},
    {"focus point not an object", [](Json &j) { j["focus"][2] = 5; }, "focus[2]"},
    {"focus point missing counts", [](Json &j) { j["focus"][3].erase("counts"); },
     "focus[3].counts"},
    {"focus point missing distance", [](Json &j) { j["focus"][3].erase("distance_m"); },
     "focus[3].distance_m"},
    {"focus point unknown field", [](Json &j) { j["focus"][1]["f_number"] = 2; },
     "focus[1].f_number"},
    {"focus counts float", [](Json &j) { j["focus"][1]["counts"] = 2100.5; }, "focus[1].counts"},
    {"focus counts string", [](Json &j) { j["focus"][1]["counts"] = "2100"; }, "focus[1].counts"},
    {"focus counts beyond int32", [](Json &j) { j["focus"][7]["counts"] = 5000000000LL; },
     "focus[7].counts"},
    {"focus counts duplicate", [](Json &j) { j["focus"][3]["counts"] = 2100; }, "focus[3].counts"},
    {"focus counts decreasing", [](Json &j) { j["focus"][3]["counts"] = 1000; }, "focus[3].counts"},
    {"focus distance zero", [](Json &j) { j["focus"][0]["distance_m"] = 0; },
     "focus[0].distance_m"},
    {"focus distance negative", [](Json &j) { j["focus"][0]["distance_m"] = -1; },
     "focus[0].distance_m"},
    {"focus distance absurd", [](Json &j) { j["focus"][6]["distance_m"] = 1e9; },
     "focus[6].distance_m"},
    {"focus distance bad string", [](Json &j) { j["focus"][7]["distance_m"] = "inf"; },
     "focus[7].distance_m"},
    {"focus distance null", [](Json &j) { j["focus"][2]["distance_m"] = nullptr; },
     "focus[2].distance_m"},
    {"focus distance repeated", [](Json &j) { j["focus"][4]["distance_m"] = 1.0; },
     "focus[4].distance_m"},
    {"focus distance turns back", [](Json &j) { j["focus"][5]["distance_m"] = 1.5; },
     "focus[5].distance_m"},
    {"focus infinity twice", [](Json &j) { j["focus"][6]["distance_m"] = "infinity"; },
     "focus[7].distance_m"},
    {"focus infinity in the middle", [](Json &j) { j["focus"][3]["distance_m"] = "infinity"; },
     "focus[4].distance_m"},
    // Iris table.
    {"iris with one point", [](Json &j) { j["iris"] = Json::array({j["iris"][0]}); }, "iris"},
    {"iris f_number missing", [](Json &j) { j["iris"][2].erase("f_number"); }, "iris[2].f_number"},
    {"iris f_number too small", [](Json &j) { j["iris"][0]["f_number"] = 0.2; },
     "iris[0].f_number"},
    {"iris f_number too large", [](Json &j) { j["iris"][7]["f_number"] = 500; },
     "iris[7].f_number"},
    {"iris f_number bool", [](Json &j) { j["iris"][1]["f_number"] = true; }, "iris[1].f_number"},
    {"iris f_number not monotone", [](Json &j) { j["iris"][4]["f_number"] = 3.5; },
     "iris[4].f_number"},
    {"iris f_number repeated", [](Json &j) { j["iris"][3]["f_number"] = 2.8; }, "iris[3].f_number"},
    {"iris counts not increasing", [](Json &j) { j["iris"][1]["counts"] = 0; }, "iris[1].counts"},
    {"iris t_stop below f_number", [](Json &j) { j["iris"][2]["t_stop"] = 2.5; }, "iris[2].t_stop"},
    {"iris t_stop on some points only", [](Json &j) { j["iris"][5].erase("t_stop"); },
     "iris[5].t_stop"},
    {"iris t_stop not monotone", [](Json &j) { j["iris"][6]["t_stop"] = 17.0; }, "iris[7].t_stop"},
    {"iris unknown field", [](Json &j) { j["iris"][0]["tstop"] = 1.5; }, "iris[0].tstop"},
    // Prime.
    {"prime not an object", [](Json &j) { j["prime"] = 35; }, "prime"},
    {"prime focal length missing", [](Json &j) { j["prime"].erase("focal_length_mm"); },
     "prime.focal_length_mm"},
    {"prime focal length zero", [](Json &j) { j["prime"]["focal_length_mm"] = 0; },
     "prime.focal_length_mm"},
    {"prime counts is unknown", [](Json &j) { j["prime"]["counts"] = 0; }, "prime.counts"},
    {"prime pupil out of range", [](Json &j) { j["prime"]["entrance_pupil_offset_mm"] = 5000; },
     "prime.entrance_pupil_offset_mm"},
    {"prime projection as string", [](Json &j) { j["prime"]["projection_focal_length_mm"] = "35"; },
     "prime.projection_focal_length_mm"},
    {"breathing with one point",
     [](Json &j) {
       auto &b = j["prime"]["projection_focal_length_mm"];
       b = Json::array({b[0]});
     },
     "prime.projection_focal_length_mm"},
    {"breathing distance repeated",
     [](Json &j) { j["prime"]["projection_focal_length_mm"][2]["distance_m"] = 0.6; },
     "prime.projection_focal_length_mm[2].distance_m"},
    {"breathing value negative",
     [](Json &j) {
       j["prime"]["projection_focal_length_mm"][1]["projection_focal_length_mm"] = -1;
     },
     "prime.projection_focal_length_mm[1].projection_focal_length_mm"},
    {"breathing unknown field",
     [](Json &j) { j["prime"]["projection_focal_length_mm"][0]["counts"] = 3; },
     "prime.projection_focal_length_mm[0].counts"},
    // Zoom table.
    {"zoom with one point", [](Json &j) { j["zoom"] = Json::array({j["zoom"][0]}); }, "zoom",
     Base::zoom},
    {"zoom counts missing", [](Json &j) { j["zoom"][1].erase("counts"); }, "zoom[1].counts",
     Base::zoom},
    {"zoom counts not increasing", [](Json &j) { j["zoom"][2]["counts"] = 500; }, "zoom[2].counts",
     Base::zoom},
    {"zoom focal length not monotone", [](Json &j) { j["zoom"][2]["focal_length_mm"] = 40; },
     "zoom[2].focal_length_mm", Base::zoom},
    {"zoom focal length repeated", [](Json &j) { j["zoom"][1]["focal_length_mm"] = 24; },
     "zoom[1].focal_length_mm", Base::zoom},
    {"zoom pupil on some points only",
     [](Json &j) { j["zoom"][2].erase("entrance_pupil_offset_mm"); },
     "zoom[2].entrance_pupil_offset_mm", Base::zoom},
    {"zoom projection on some points only",
     [](Json &j) { j["zoom"][1]["projection_focal_length_mm"] = 50.1; },
     "zoom[1].projection_focal_length_mm", Base::zoom},
    // Per-zoom focus tables (version 2).
    {"version 1 zoom point with a focus table", [](Json &j) { j["zoom"][1]["focus"] = j["focus"]; },
     "zoom[1].focus", Base::zoom},
    {"version 2 with a top-level focus too", [](Json &j) { j["focus"] = example()["focus"]; },
     "version", Base::per_zoom},
    {"version 2 prime",
     [](Json &j) {
       j["version"] = 2;
       j.erase("focus");
     },
     "version"},
    {"version 2 zoom point without focus", [](Json &j) { j["zoom"][2].erase("focus"); },
     "zoom[2].focus", Base::per_zoom},
    {"version 2 focus not an array", [](Json &j) { j["zoom"][0]["focus"] = 3; }, "zoom[0].focus",
     Base::per_zoom},
    {"version 2 focus with one point",
     [](Json &j) { j["zoom"][1]["focus"] = Json::array({j["zoom"][1]["focus"][0]}); },
     "zoom[1].focus", Base::per_zoom},
    {"version 2 focus counts not increasing",
     [](Json &j) { j["zoom"][2]["focus"][3]["counts"] = 100; }, "zoom[2].focus[3].counts",
     Base::per_zoom},
    {"version 2 focus distance turns back",
     [](Json &j) { j["zoom"][1]["focus"][5]["distance_m"] = 1.5; }, "zoom[1].focus[5].distance_m",
     Base::per_zoom},
    {"version 2 focus unknown field", [](Json &j) { j["zoom"][0]["focus"][1]["f_number"] = 2; },
     "zoom[0].focus[1].f_number", Base::per_zoom},
    {"version 2 focus tables of opposite directions",
     [](Json &j) {
       Json &t = j["zoom"][2]["focus"];
       const Json d = t;
       for (std::size_t i = 0; i < t.size(); ++i)
         t[i]["distance_m"] = d[t.size() - 1 - i]["distance_m"];
     },
     "zoom[2].focus", Base::per_zoom},
    // Distortion.
    {"distortion not an object",
     [](Json &j) {
       j["distortion"] = Json::array({1, 2});
     },
     "distortion"},
    {"distortion unknown coefficient", [](Json &j) { j["distortion"]["k4"] = 0.1; },
     "distortion.k4"},
    {"distortion coefficient huge", [](Json &j) { j["distortion"]["k2"] = 1e6; }, "distortion.k2"},
    {"distortion coefficient string", [](Json &j) { j["distortion"]["p1"] = "0"; },
     "distortion.p1"},
};

TEST(ProfileErrors, EachRuleNamesFileAndField) {
  for (const BadCase &c : kCases) {
    Json j = c.base == Base::zoom       ? zoom_base()
             : c.base == Base::per_zoom ? per_zoom_base()
                                        : example();
    c.edit(j);
    try {
      (void)LensProfile::parse(j.dump(), kSource);
      ADD_FAILURE() << c.what << ": accepted";
    } catch (const ProfileError &e) {
      EXPECT_EQ(e.file(), kSource) << c.what;
      EXPECT_EQ(e.field(), c.field) << c.what << ": " << e.what();
      const std::string prefix =
          std::string(kSource) + ": " + (e.field().empty() ? "" : e.field() + ": ");
      EXPECT_EQ(std::string(e.what()).rfind(prefix, 0), 0u) << e.what();
      EXPECT_FALSE(e.reason().empty()) << c.what;
    }
  }
}

TEST(ProfileErrors, BaseProfilesAreValid) {
  EXPECT_NO_THROW((void)LensProfile::parse(example().dump(), kSource));
  EXPECT_NO_THROW((void)LensProfile::parse(zoom_base().dump(), kSource));
  EXPECT_NO_THROW((void)LensProfile::parse(per_zoom_base().dump(), kSource));
}

TEST(ProfileErrors, OppositeFocusDirectionsAreExplained) {
  Json j = per_zoom_base();
  Json &t = j["zoom"][1]["focus"];
  const Json d = t;
  for (std::size_t i = 0; i < t.size(); ++i)
    t[i]["distance_m"] = d[t.size() - 1 - i]["distance_m"];
  try {
    (void)LensProfile::parse(j.dump(), kSource);
    FAIL() << "accepted";
  } catch (const ProfileError &e) {
    EXPECT_STREQ(e.what(),
                 "/virtual/bad_lens.json: zoom[1].focus: runs the other way from zoom[0].focus "
                 "(distance falls as counts rise here, distance rises as counts rise there): "
                 "every zoom point's focus table must run the same way, or the blend between "
                 "them would run backwards");
  }
}

TEST(ProfileErrors, SyntaxErrorsAndMissingFiles) {
  for (const char *text : {"", "{", "{\"format\": }", "[1, 2", "nul", "{\"a\": 1,}", "\x01"}) {
    try {
      (void)LensProfile::parse(text, kSource);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const ProfileError &e) {
      EXPECT_EQ(e.file(), kSource);
      EXPECT_NE(e.reason().find("invalid JSON"), std::string::npos) << e.what();
    }
  }
  try {
    (void)LensProfile::load("/nonexistent/lens.json");
    ADD_FAILURE() << "loaded a missing file";
  } catch (const ProfileError &e) {
    EXPECT_EQ(e.file(), "/nonexistent/lens.json");
  }
}

// A focus distance so small that 1/d overflows (1e-310 m) is an error on
// its field, not an internal invariant of the curve fitted through it.
TEST(ProfileErrors, TinyFocusDistanceFailsOnItsField) {
  Json j = example();
  j["focus"][0]["distance_m"] = 1e-310;
  try {
    (void)LensProfile::parse(j.dump(), kSource);
    ADD_FAILURE() << "1e-310 m accepted";
  } catch (const ProfileError &e) {
    EXPECT_NE(std::string(e.what()).find("focus[0].distance_m: must be within 0.001 .. 100000"),
              std::string::npos)
        << e.what();
  }
}

TEST(ProfileErrors, NonFiniteAndHugeLiteralsFailOnTheirField) {
  // nlohmann refuses these while parsing; the reader names the field instead.
  const std::string text = example().dump();
  const std::string key = "\"focal_length_mm\":";
  ASSERT_NE(text.find(key), std::string::npos);
  for (const std::string &literal :
       {std::string("1e999"), std::string("NaN"), std::string("NaN4"), std::string(400, '7')}) {
    std::string t = text;
    const std::size_t at = t.find(key) + key.size();
    t.replace(at, t.find_first_of(",}", at) - at, literal);
    try {
      (void)LensProfile::parse(t, kSource);
      ADD_FAILURE() << literal.substr(0, 20) << " accepted";
    } catch (const ProfileError &e) {
      EXPECT_STREQ(e.what(),
                   "/virtual/bad_lens.json: prime.focal_length_mm: must be a finite number");
    }
  }
}

TEST(ProfileErrors, DamagedTextNeverCrashes) {
  // Byte flips, truncations and deletions of a valid file: every outcome must
  // be a profile or a ProfileError, nothing else.
  const std::string good = example().dump(1);
  std::mt19937 rng(1234);
  int rejected = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string s = good;
    const std::size_t at = std::uniform_int_distribution<std::size_t>(0, s.size() - 1)(rng);
    switch (trial % 3) {
    case 0:
      s[at] = char(std::uniform_int_distribution<int>(0, 255)(rng));
      break;
    case 1:
      s.resize(at);
      break;
    default:
      s.erase(at, std::uniform_int_distribution<std::size_t>(1, 12)(rng));
    }
    try {
      (void)LensProfile::parse(s, kSource);
    } catch (const ProfileError &) {
      ++rejected;
    } catch (const std::exception &e) {
      ADD_FAILURE() << "trial " << trial << " threw something else: " << e.what();
    }
  }
  EXPECT_GT(rejected, 1000);
}

} // namespace
} // namespace camhead::lens_control
