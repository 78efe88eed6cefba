// OpenTrackIO binary header: the checksum algorithm, a hand-assembled
// datagram, round trips, and every corruption of the 16-byte header.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "camhead/hal/lens/network/opentrackio.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

std::vector<std::uint8_t> bytes_of(std::string_view text) {
  return {text.begin(), text.end()};
}

std::vector<std::uint8_t> wrap(std::string_view json, std::uint16_t sequence = 7) {
  return encode_opentrackio_datagram(bytes_of(json), sequence);
}

// Rewrites the checksum after a deliberate header edit, so that the check
// under test is the one that fires.
void reseal(std::vector<std::uint8_t> &d) {
  const std::uint16_t sum = fletcher16(std::span(d).first(14), std::span(d).subspan(16));
  d[14] = static_cast<std::uint8_t>(sum >> 8);
  d[15] = static_cast<std::uint8_t>(sum);
}

// The test vectors of the published Fletcher-16 description (Wikipedia,
// "Fletcher's checksum"): they pin the modulus 255 and the (sum2 << 8) | sum1
// order.
TEST(OpenTrackIoHeader, Fletcher16MatchesPublishedVectors) {
  EXPECT_EQ(fletcher16(bytes_of("abcde")), 0xC8F0);
  EXPECT_EQ(fletcher16(bytes_of("abcdef")), 0x2057);
  EXPECT_EQ(fletcher16(bytes_of("abcdefgh")), 0x0627);
  // Header and payload are summed as one stream.
  EXPECT_EQ(fletcher16(bytes_of("abc"), bytes_of("def")), 0x2057);
  EXPECT_EQ(fletcher16({}), 0x0000);
}

// Assembled by hand from the header layout; the checksum 0x92D3 was computed
// with an independent Python implementation of the same Fletcher-16.
TEST(OpenTrackIoHeader, ParsesHandAssembledDatagram) {
  const std::string payload = R"({"lens":{"focusDistance":2.5}})"; // 30 bytes
  std::vector<std::uint8_t> d = {
      'O',  'T',  'r',  'k',  // identifier
      0x00,                   // reserved
      0x01,                   // JSON
      0x00, 0x2A,             // sequence 42
      0x00, 0x00, 0x00, 0x00, // segment offset
      0x80, 30,               // last segment, 30 bytes
      0x92, 0xD3,             // Fletcher-16
  };
  d.insert(d.end(), payload.begin(), payload.end());
  const OpenTrackIoParseResult r = parse_opentrackio(d);
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.sample->header_sequence, 42);
  EXPECT_EQ(r.sample->focus_distance_m, 2.5);
  EXPECT_FALSE(r.sample->f_stop);
  EXPECT_EQ(encode_opentrackio_datagram(bytes_of(payload), 42), d);
}

TEST(OpenTrackIoHeader, RoundTripsEveryField) {
  OpenTrackIoSample lens;
  lens.header_sequence = 0xFFFF;
  lens.focus_distance_m = 3.25;
  lens.f_stop = 2.8;
  lens.pinhole_focal_length_mm = 35.123456789;
  lens.encoder_focus = 0.0;
  lens.encoder_iris = 0.1;
  lens.encoder_zoom = 1.0;
  lens.sample_sequence = 18446744073709551615u;
  lens.sample_timestamp = OpenTrackIoTimestamp{1718000000, 999999999};
  lens.sample_id = "urn:uuid:5ca5f233-11b5-4f43-8815-948d73e48a33";
  const auto d = encode_opentrackio(lens);
  ASSERT_FALSE(d.empty());
  const OpenTrackIoParseResult r = parse_opentrackio(d);
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(*r.sample, lens);
}

TEST(OpenTrackIoHeader, RoundTripsEmptySample) {
  const OpenTrackIoParseResult r = parse_opentrackio(encode_opentrackio(OpenTrackIoSample{}));
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(*r.sample, OpenTrackIoSample{});
}

TEST(OpenTrackIoHeader, RejectsEveryTruncation) {
  const auto d = wrap(R"({"lens":{"fStop":4}})");
  for (std::size_t n = 0; n < d.size(); ++n) {
    const OpenTrackIoParseResult r = parse_opentrackio(std::span(d).first(n));
    EXPECT_FALSE(r) << n;
    EXPECT_EQ(r.error, n < kOpenTrackIoHeaderSize ? OpenTrackIoError::truncated
                                                  : OpenTrackIoError::length_mismatch)
        << n;
  }
}

TEST(OpenTrackIoHeader, RejectsTrailingBytes) {
  auto d = wrap(R"({"lens":{"fStop":4}})");
  d.push_back('\n');
  const OpenTrackIoParseResult r = parse_opentrackio(d);
  EXPECT_EQ(r.error, OpenTrackIoError::length_mismatch) << r.detail;
}

TEST(OpenTrackIoHeader, RejectsBadMagic) {
  auto d = wrap("{}");
  d[3] = 'K';
  reseal(d);
  const OpenTrackIoParseResult r = parse_opentrackio(d);
  EXPECT_EQ(r.error, OpenTrackIoError::bad_magic) << r.detail;
}

TEST(OpenTrackIoHeader, RejectsBadChecksum) {
  auto d = wrap("{}");
  d[15] ^= 0x01;
  const OpenTrackIoParseResult r = parse_opentrackio(d);
  EXPECT_EQ(r.error, OpenTrackIoError::bad_checksum) << r.detail;
}

TEST(OpenTrackIoHeader, RejectsCborWithClearReason) {
  const auto d = encode_opentrackio_datagram(std::vector<std::uint8_t>{0xA0}, 1, kOpenTrackIoCbor);
  const OpenTrackIoParseResult r = parse_opentrackio(d);
  EXPECT_EQ(r.error, OpenTrackIoError::unsupported_encoding);
  EXPECT_NE(r.detail.find("CBOR"), std::string::npos) << r.detail;
}

TEST(OpenTrackIoHeader, RejectsUnknownEncoding) {
  const auto d = encode_opentrackio_datagram(bytes_of("{}"), 1, 0x80);
  const OpenTrackIoParseResult r = parse_opentrackio(d);
  EXPECT_EQ(r.error, OpenTrackIoError::unsupported_encoding);
  EXPECT_NE(r.detail.find("128"), std::string::npos) << r.detail;
}

TEST(OpenTrackIoHeader, RejectsFirstSegmentOfSeveral) {
  auto d = wrap("{}");
  d[12] &= 0x7F; // more segments follow
  reseal(d);
  const OpenTrackIoParseResult r = parse_opentrackio(d);
  EXPECT_EQ(r.error, OpenTrackIoError::multi_segment);
  EXPECT_NE(r.detail.find("segment"), std::string::npos) << r.detail;
}

TEST(OpenTrackIoHeader, RejectsLaterSegment) {
  auto d = wrap("{}");
  d[11] = 0x10; // last segment, but at offset 16
  reseal(d);
  const OpenTrackIoParseResult r = parse_opentrackio(d);
  EXPECT_EQ(r.error, OpenTrackIoError::multi_segment) << r.detail;
}

TEST(OpenTrackIoHeader, IgnoresReservedByte) {
  auto d = wrap(R"({"lens":{"fStop":4}})");
  d[4] = 0x5A;
  reseal(d);
  const OpenTrackIoParseResult r = parse_opentrackio(d);
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.sample->f_stop, 4.0);
}

TEST(OpenTrackIoHeader, EncoderRefusesOversizedPayload) {
  const std::vector<std::uint8_t> big(kOpenTrackIoMaxPayload + 1, ' ');
  EXPECT_TRUE(encode_opentrackio_datagram(big, 1).empty());
  const std::vector<std::uint8_t> max(kOpenTrackIoMaxPayload, ' ');
  EXPECT_EQ(encode_opentrackio_datagram(max, 1).size(), kOpenTrackIoHeaderSize + max.size());
}

// A single flipped bit changes one byte by +-2^k, which is never 0 modulo
// 255, so Fletcher-16's first sum always moves: every flip is rejected.
// Flips in the identifier or the length field are caught by those checks
// before the checksum is even computed.
TEST(OpenTrackIoHeader, RejectsEverySingleBitFlip) {
  const auto valid = wrap(R"({"lens":{"encoders":{"focus":0.5}}})");
  for (std::size_t byte = 0; byte < valid.size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      auto d = valid;
      d[byte] ^= static_cast<std::uint8_t>(1u << bit);
      const OpenTrackIoParseResult r = parse_opentrackio(d);
      EXPECT_FALSE(r) << "byte " << byte << " bit " << bit;
      if (byte < 4) {
        EXPECT_EQ(r.error, OpenTrackIoError::bad_magic) << byte;
      } else if ((byte == 12 && bit < 7) || byte == 13) {
        EXPECT_EQ(r.error, OpenTrackIoError::length_mismatch) << byte << " " << bit;
      } else {
        EXPECT_EQ(r.error, OpenTrackIoError::bad_checksum) << byte << " " << bit;
      }
    }
  }
}

} // namespace
} // namespace camhead::hal::lens
