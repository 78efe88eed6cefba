// OpenTrackIO JSON payload: a realistic sample, absent fields, and every
// rejection naming the field that caused it. The header is always valid here
// (encode_opentrackio_datagram), so only the payload is under test.
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

// Shaped like the OpenTrackIO example samples: tracker and transform data we
// do not read sit next to the lens object and must not disturb it.
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
  const OpenTrackIoLens &l = *r.lens;
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
}

TEST(OpenTrackIoFields, AbsentFieldsStayEmpty) {
  const OpenTrackIoParseResult r = parse_payload(R"({"lens":{"encoders":{"zoom":0.5}}})");
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.lens->encoder_zoom, 0.5);
  EXPECT_FALSE(r.lens->encoder_focus);
  EXPECT_FALSE(r.lens->encoder_iris);
  EXPECT_FALSE(r.lens->focus_distance_m);
  EXPECT_FALSE(r.lens->sample_timestamp);
  EXPECT_FALSE(r.lens->sample_id);
}

TEST(OpenTrackIoFields, TrackerOnlySampleHasNoLensFields) {
  const OpenTrackIoParseResult r = parse_payload(R"({"tracker":{"status":"ok"}})");
  ASSERT_TRUE(r) << r.detail;
  OpenTrackIoLens expected;
  expected.header_sequence = 3;
  EXPECT_EQ(*r.lens, expected);
}

TEST(OpenTrackIoFields, EncoderBoundsAndIntegerNumbersAreAccepted) {
  const OpenTrackIoParseResult r =
      parse_payload(R"({"lens":{"encoders":{"focus":0,"iris":1,"zoom":1.0},"fStop":2}})");
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.lens->encoder_focus, 0.0);
  EXPECT_EQ(r.lens->encoder_iris, 1.0);
  EXPECT_EQ(r.lens->encoder_zoom, 1.0);
  EXPECT_EQ(r.lens->f_stop, 2.0);
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
