// OpenTrackIO JSON payload: a realistic sample, absent fields, and every
// rejection naming the field that caused it. The header is always valid here
// (encode_opentrackio_datagram), so only the payload is under test.
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "camhead/hal/lens/network/opentrackio.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

OpenTrackIoParseResult parse_payload(std::string_view json) {
  const std::vector<std::uint8_t> payload(json.begin(), json.end());
  return parse_opentrackio(encode_opentrackio_datagram(payload, 3));
}

// Shaped like the OpenTrackIO example samples: tracker data we do not read
// sits next to the lens object and the transforms and must not disturb them.
constexpr std::string_view kFullSample = R"({
  "protocol": {"name": "OpenTrackIO", "version": [1, 0, 0]},
  "sampleId": "urn:uuid:0b6c0a3e-2f7e-4b7a-9a4e-6f1d2c3b4a59",
  "sourceId": "urn:uuid:2b0a5c8e-1d3f-4e6a-8b7c-9d0e1f2a3b4c",
  "sourceNumber": 1,
  "timing": {
    "mode": "internal",
    "sampleRate": {"num": 24000, "denom": 1001},
    "sampleTimestamp": {"seconds": 1718000000, "nanoseconds": 41666667, "attoseconds": 0},
    "sequenceNumber": 1234,
    "timecode": {"hours": 1, "minutes": 2, "seconds": 3, "frames": 4,
                 "frameRate": {"num": 24, "denom": 1}}
  },
  "tracker": {"notes": "x", "recording": false, "slate": "A101", "status": "Optical Good"},
  "transforms": [{"translation": {"x": 1.0, "y": 2.0, "z": 3.0},
                  "rotation": {"pan": 180.0, "tilt": 90.0, "roll": 45.0}, "id": "Camera"}],
  "lens": {
    "distortion": [{"radial": [1.0, 2.0, 3.0], "tangential": [1.0, 2.0]}],
    "encoders": {"focus": 0.1, "iris": 0.2, "zoom": 0.3},
    "entrancePupilOffset": 0.123,
    "fStop": 4.0,
    "focusDistance": 10.0,
    "pinholeFocalLength": 24.305,
    "rawEncoders": {"focus": 1000, "iris": 2000, "zoom": 3000},
    "tStop": 4.1
  }
})";

TEST(OpenTrackIoFields, ExtractsLensFromFullSample) {
  const OpenTrackIoParseResult r = parse_payload(kFullSample);
  ASSERT_TRUE(r) << r.detail;
  const OpenTrackIoSample &l = *r.sample;
  EXPECT_EQ(l.header_sequence, 3);
  EXPECT_EQ(l.focus_distance_m, 10.0);
  EXPECT_EQ(l.f_stop, 4.0);
  EXPECT_EQ(l.pinhole_focal_length_mm, 24.305);
  EXPECT_EQ(l.encoder_focus, 0.1);
  EXPECT_EQ(l.encoder_iris, 0.2);
  EXPECT_EQ(l.encoder_zoom, 0.3);
  EXPECT_EQ(l.sample_sequence, 1234u);
  ASSERT_TRUE(l.sample_timestamp);
  EXPECT_EQ(l.sample_timestamp->seconds, 1718000000u);
  EXPECT_EQ(l.sample_timestamp->nanoseconds, 41666667u);
  EXPECT_EQ(l.sample_id, "urn:uuid:0b6c0a3e-2f7e-4b7a-9a4e-6f1d2c3b4a59");
  ASSERT_EQ(l.transforms.size(), 1u);
  EXPECT_EQ(l.transforms[0].id, "Camera");
  EXPECT_EQ(l.transforms[0].pose, (TrackedPose{.x_m = 1.0,
                                               .y_m = 2.0,
                                               .z_m = 3.0,
                                               .pan_deg = 180.0,
                                               .tilt_deg = 90.0,
                                               .roll_deg = 45.0}));
  EXPECT_EQ(opentrackio_camera_pose(l.transforms), l.transforms[0].pose)
      << "one transform is the camera's pose as sent";
}

TEST(OpenTrackIoFields, TransformsComposeInOrder) {
  // A tracking origin 1 m to the right turned 90 degrees to the left, then
  // the camera 2 m ahead of it, tilted and rolled: 2 m along the origin's
  // forward, which points along -X.
  const OpenTrackIoParseResult r = parse_payload(R"({"transforms": [
      {"translation": {"x": 1, "y": 0, "z": 0}, "rotation": {"pan": 90, "tilt": 0, "roll": 0},
       "scale": {"x": 1, "y": 1, "z": 1}},
      {"translation": {"x": 0, "y": 2, "z": 0.5}, "rotation": {"pan": -60, "tilt": 20, "roll": 15}}
    ]})");
  ASSERT_TRUE(r) << r.detail;
  ASSERT_EQ(r.sample->transforms.size(), 2u);
  EXPECT_FALSE(r.sample->transforms[0].id);
  const std::optional<TrackedPose> camera = opentrackio_camera_pose(r.sample->transforms);
  ASSERT_TRUE(camera);
  EXPECT_NEAR(camera->x_m, -1.0, 1e-12);
  EXPECT_NEAR(camera->y_m, 0.0, 1e-12);
  EXPECT_NEAR(camera->z_m, 0.5, 1e-12);
  EXPECT_NEAR(camera->pan_deg, 30.0, 1e-9) << "pans about the same vertical add";
  EXPECT_NEAR(camera->tilt_deg, 20.0, 1e-9);
  EXPECT_NEAR(camera->roll_deg, 15.0, 1e-9);
  EXPECT_FALSE(opentrackio_camera_pose({})) << "no transforms, no pose";
}

TEST(OpenTrackIoFields, TransformsSurviveEncodeAndParse) {
  OpenTrackIoSample sample;
  sample.header_sequence = 9;
  sample.transforms.push_back({.pose = {.x_m = 0.25, .pan_deg = -170.5}, .id = "Stage"});
  sample.transforms.push_back({.pose = {.y_m = -3.0, .z_m = 1.5, .tilt_deg = -5, .roll_deg = 2}});
  const OpenTrackIoParseResult r = parse_opentrackio(encode_opentrackio(sample));
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(*r.sample, sample);
}

TEST(OpenTrackIoFields, AbsentFieldsStayEmpty) {
  const OpenTrackIoParseResult r = parse_payload(R"({"lens":{"encoders":{"zoom":0.5}}})");
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.sample->encoder_zoom, 0.5);
  EXPECT_FALSE(r.sample->encoder_focus);
  EXPECT_FALSE(r.sample->encoder_iris);
  EXPECT_FALSE(r.sample->focus_distance_m);
  EXPECT_FALSE(r.sample->sample_timestamp);
  EXPECT_FALSE(r.sample->sample_id);
}

TEST(OpenTrackIoFields, TrackerOnlySampleHasNoLensFields) {
  const OpenTrackIoParseResult r = parse_payload(R"({"tracker":{"status":"ok"}})");
  ASSERT_TRUE(r) << r.detail;
  OpenTrackIoSample expected;
  expected.header_sequence = 3;
  EXPECT_EQ(*r.sample, expected);
}

TEST(OpenTrackIoFields, EncoderBoundsAndIntegerNumbersAreAccepted) {
  const OpenTrackIoParseResult r =
      parse_payload(R"({"lens":{"encoders":{"focus":0,"iris":1,"zoom":1.0},"fStop":2}})");
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.sample->encoder_focus, 0.0);
  EXPECT_EQ(r.sample->encoder_iris, 1.0);
  EXPECT_EQ(r.sample->encoder_zoom, 1.0);
  EXPECT_EQ(r.sample->f_stop, 2.0);
}

struct BadPayload {
  const char *name;
  std::string_view json;
  OpenTrackIoError error;
  std::string_view field; // must appear in the detail
};

void PrintTo(const BadPayload &p, std::ostream *os) {
  *os << p.name;
}

class OpenTrackIoRejects : public testing::TestWithParam<BadPayload> {};

TEST_P(OpenTrackIoRejects, WithReasonNamingTheField) {
  const BadPayload &p = GetParam();
  const OpenTrackIoParseResult r = parse_payload(p.json);
  EXPECT_FALSE(r);
  EXPECT_EQ(r.error, p.error) << to_string(r.error) << ": " << r.detail;
  EXPECT_NE(r.detail.find(p.field), std::string::npos) << r.detail;
}

using E = OpenTrackIoError;
const BadPayload kBadPayloads[] = {
    // Malformed JSON.
    {"Empty", "", E::malformed_json, "malformed JSON"},
    {"TruncatedJson", R"({"lens":{"fStop":)", E::malformed_json, "lens.fStop"},
    {"TrailingGarbage", R"({"lens":{}} x)", E::malformed_json, "malformed JSON"},
    {"TwoDocuments", R"({} {})", E::malformed_json, "malformed JSON"},
    {"InvalidUtf8", "{\"sampleId\":\"\xC3\x28\"}", E::malformed_json, "malformed JSON"},
    {"NanLiteral", R"({"lens":{"fStop":NaN}})", E::malformed_json, "lens.fStop"},
    // Numbers that no double can hold.
    {"OverflowFocusDistance", R"({"lens":{"focusDistance":1e999}})", E::non_finite,
     "lens.focusDistance"},
    {"OverflowEncoder", R"({"lens":{"encoders":{"iris":-1e400}}})", E::non_finite,
     "lens.encoders.iris"},
    // Wrong JSON types.
    {"SampleNotObject", R"([1,2,3])", E::wrong_type, "sample"},
    {"LensNotObject", R"({"lens":[]})", E::wrong_type, "lens"},
    {"EncodersNotObject", R"({"lens":{"encoders":0.5}})", E::wrong_type, "lens.encoders"},
    {"FocusDistanceString", R"({"lens":{"focusDistance":"2.5"}})", E::wrong_type,
     "lens.focusDistance"},
    {"FStopNull", R"({"lens":{"fStop":null}})", E::wrong_type, "lens.fStop"},
    {"FocalLengthBool", R"({"lens":{"pinholeFocalLength":true}})", E::wrong_type,
     "lens.pinholeFocalLength"},
    {"EncoderFocusString", R"({"lens":{"encoders":{"focus":"0.5"}}})", E::wrong_type,
     "lens.encoders.focus"},
    {"TimingNotObject", R"({"timing":1})", E::wrong_type, "timing"},
    {"SequenceFloat", R"({"timing":{"sequenceNumber":1.5}})", E::wrong_type,
     "timing.sequenceNumber"},
    {"TimestampNotObject", R"({"timing":{"sampleTimestamp":"now"}})", E::wrong_type,
     "timing.sampleTimestamp"},
    {"TimestampNoSeconds", R"({"timing":{"sampleTimestamp":{"nanoseconds":1}}})", E::wrong_type,
     "timing.sampleTimestamp.seconds"},
    {"TimestampNoNanoseconds", R"({"timing":{"sampleTimestamp":{"seconds":1}}})", E::wrong_type,
     "timing.sampleTimestamp.nanoseconds"},
    {"SampleIdNumber", R"({"sampleId":5})", E::wrong_type, "sampleId"},
    {"TransformsNotArray", R"({"transforms":{"translation":{}}})", E::wrong_type, "transforms"},
    {"TransformNotObject", R"({"transforms":[1]})", E::wrong_type, "transforms[0]"},
    {"TransformNoRotation",
     R"({"transforms":[{"translation":{"x":0,"y":0,"z":0},"rotation":{"pan":0,"tilt":0,"roll":0}},
                       {"translation":{"x":0,"y":0,"z":0}}]})",
     E::wrong_type, "transforms[1].rotation: missing"},
    {"TransformNoTranslation", R"({"transforms":[{"rotation":{"pan":0,"tilt":0,"roll":0}}]})",
     E::wrong_type, "transforms[0].translation: missing"},
    {"TranslationNoZ",
     R"({"transforms":[{"translation":{"x":0,"y":0},"rotation":{"pan":0,"tilt":0,"roll":0}}]})",
     E::wrong_type, "transforms[0].translation.z: missing"},
    {"PanString",
     R"({"transforms":[{"translation":{"x":0,"y":0,"z":0},"rotation":{"pan":"0","tilt":0,"roll":0}}]})",
     E::wrong_type, "transforms[0].rotation.pan"},
    {"RotationArray", R"({"transforms":[{"translation":{"x":0,"y":0,"z":0},"rotation":[0,0,0]}]})",
     E::wrong_type, "transforms[0].rotation"},
    {"TransformIdNumber",
     R"({"transforms":[{"id":7,"translation":{"x":0,"y":0,"z":0},"rotation":{"pan":0,"tilt":0,"roll":0}}]})",
     E::wrong_type, "transforms[0].id"},
    {"OverflowTilt",
     R"({"transforms":[{"translation":{"x":0,"y":0,"z":0},"rotation":{"pan":0,"tilt":1e999,"roll":0}}]})",
     // Caught while parsing, before the elements are counted.
     E::non_finite, "transforms[].rotation.tilt"},
    // Out of range.
    {"EncoderFocusAboveOne", R"({"lens":{"encoders":{"focus":1.0000001}}})", E::out_of_range,
     "lens.encoders.focus"},
    {"EncoderIrisAboveOne", R"({"lens":{"encoders":{"iris":1.5}}})", E::out_of_range,
     "lens.encoders.iris"},
    {"EncoderZoomNegative", R"({"lens":{"encoders":{"zoom":-0.1}}})", E::out_of_range,
     "lens.encoders.zoom"},
    {"FocusDistanceZero", R"({"lens":{"focusDistance":0}})", E::out_of_range, "lens.focusDistance"},
    {"FStopNegative", R"({"lens":{"fStop":-2.8}})", E::out_of_range, "lens.fStop"},
    {"FocalLengthZero", R"({"lens":{"pinholeFocalLength":0.0}})", E::out_of_range,
     "lens.pinholeFocalLength"},
    {"SequenceNegative", R"({"timing":{"sequenceNumber":-1}})", E::out_of_range,
     "timing.sequenceNumber"},
    {"NanosecondsTooLarge",
     R"({"timing":{"sampleTimestamp":{"seconds":1,"nanoseconds":1000000000}}})", E::out_of_range,
     "timing.sampleTimestamp.nanoseconds"},
};

INSTANTIATE_TEST_SUITE_P(Payloads, OpenTrackIoRejects, testing::ValuesIn(kBadPayloads),
                         [](const testing::TestParamInfo<BadPayload> &param_info) {
                           return std::string{param_info.param.name};
                         });

TEST(OpenTrackIoFields, FirstBadFieldWins) {
  // Both fields are wrong; the report must name one field, not a mixture.
  const OpenTrackIoParseResult r = parse_payload(R"({"lens":{"fStop":"x","encoders":{"zoom":7}}})");
  EXPECT_EQ(r.error, OpenTrackIoError::wrong_type);
  EXPECT_NE(r.detail.find("lens.fStop"), std::string::npos) << r.detail;
  EXPECT_EQ(r.detail.find("zoom"), std::string::npos) << r.detail;
}

// The largest payload nests 16k deep: neither parsing, nor locating the
// error, nor destroying the document may recurse once per level.
TEST(OpenTrackIoFields, DeepNestingIsRejectedWithoutRecursion) {
  const std::size_t depth = kOpenTrackIoMaxPayload / 2;
  const std::string closed = std::string(depth, '[') + std::string(depth, ']');
  OpenTrackIoParseResult r = parse_payload(closed);
  EXPECT_EQ(r.error, OpenTrackIoError::wrong_type) << r.detail;
  const std::string open = R"({"lens":)" + std::string(kOpenTrackIoMaxPayload - 8, '[');
  r = parse_payload(open);
  EXPECT_EQ(r.error, OpenTrackIoError::malformed_json);
  EXPECT_LT(r.detail.size(), 200u)
      << "detail should be clipped for logs: " << r.detail.substr(0, 200);
}

TEST(OpenTrackIoFields, ErrorNamesAreDistinct) {
  std::vector<std::string> names;
  for (int e = 0; e <= static_cast<int>(OpenTrackIoError::non_finite); ++e) {
    const std::string name = to_string(static_cast<OpenTrackIoError>(e));
    for (const std::string &other : names) {
      EXPECT_NE(name, other);
    }
    names.push_back(name);
  }
}

} // namespace
} // namespace camhead::hal::lens
