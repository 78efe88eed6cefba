// FreeD D1: a hand-assembled message from the published layout, round trips,
// and every kind of corruption a UDP or RS-422 link can deliver.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "camhead/hal/lens/network/freed.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

// Assembled by hand from the layout, independently of the encoder:
//   camera 1, pan +90 deg, tilt -45 deg, roll 0,
//   X +1000 mm, Y -500 mm, Z +1500 mm, zoom 0xABCD, focus 0x0800, user 0.
//   pan   90 * 32768 = 2949120 = 0x2D0000
//   tilt -45 * 32768 = -1474560 -> 0x1000000 - 0x168000 = 0xE98000
//   X   1000 * 64 = 64000 = 0x00FA00
//   Y   -500 * 64 = -32000 -> 0x1000000 - 0x7D00 = 0xFF8300
//   Z   1500 * 64 = 96000 = 0x017700
// Checksum: the non-zero bytes sum to
//   D1+01+2D+E9+80+FA+FF+83+01+77+AB+CD+08
//   = 209+1+45+233+128+250+255+131+1+119+171+205+8 = 1756 = 6*256 + 220 (0xDC)
//   and (0x40 - 0xDC) mod 256 = (64 - 220 + 256) = 100 = 0x64.
constexpr std::array<std::uint8_t, kFreedD1Size> kKnown = {
    0xD1, 0x01,       // type, camera id
    0x2D, 0x00, 0x00, // pan
    0xE9, 0x80, 0x00, // tilt
    0x00, 0x00, 0x00, // roll
    0x00, 0xFA, 0x00, // X
    0xFF, 0x83, 0x00, // Y
    0x01, 0x77, 0x00, // Z
    0x00, 0xAB, 0xCD, // zoom
    0x00, 0x08, 0x00, // focus
    0x00, 0x00,       // user
    0x64,             // checksum
};

FreedD1 known_message() {
  FreedD1 m;
  m.camera_id = 1;
  m.pan_deg = 90.0;
  m.tilt_deg = -45.0;
  m.roll_deg = 0.0;
  m.x_mm = 1000.0;
  m.y_mm = -500.0;
  m.z_mm = 1500.0;
  m.zoom = 0xABCD;
  m.focus = 0x0800;
  m.user = 0;
  return m;
}

TEST(FreedD1, ChecksumOfHandAssembledMessage) {
  EXPECT_EQ(freed_checksum(std::span(kKnown).first(28)), 0x64);
}

TEST(FreedD1, ParsesHandAssembledMessage) {
  const FreedParseResult r = parse_freed_d1(kKnown);
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.error, FreedError::none);
  EXPECT_TRUE(r.detail.empty());
  EXPECT_EQ(*r.message, known_message());
}

TEST(FreedD1, EncoderReproducesHandAssembledMessage) {
  EXPECT_EQ(encode_freed_d1(known_message()), kKnown);
}

TEST(FreedD1, SignExtendsTwentyFourBitFields) {
  auto bytes = kKnown;
  // pan 0x800000 (most negative), tilt 0xFFFFFF (-1 step), roll 0x7FFFFF (most positive)
  const std::array<std::uint8_t, 9> angles = {0x80, 0, 0, 0xFF, 0xFF, 0xFF, 0x7F, 0xFF, 0xFF};
  std::copy(angles.begin(), angles.end(), bytes.begin() + 2);
  // zoom 0xFFFFFF is unsigned: it must not come out negative.
  bytes[20] = bytes[21] = bytes[22] = 0xFF;
  bytes[26] = 0xBE;
  bytes[27] = 0xEF;
  bytes[28] = freed_checksum(std::span(bytes).first(28));
  const FreedParseResult r = parse_freed_d1(bytes);
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.message->pan_deg, -256.0);
  EXPECT_EQ(r.message->tilt_deg, -1.0 / 32768.0);
  EXPECT_EQ(r.message->roll_deg, 0x7FFFFF / 32768.0);
  EXPECT_EQ(r.message->zoom, 0xFFFFFFu);
  EXPECT_EQ(r.message->user, 0xBEEF);
}

TEST(FreedD1, RoundTripsRepresentableValues) {
  std::vector<FreedD1> messages = {known_message(), FreedD1{}};
  FreedD1 extreme;
  extreme.camera_id = 255;
  extreme.pan_deg = -256.0;
  extreme.tilt_deg = 0x7FFFFF / kFreedAngleScale;
  extreme.roll_deg = 1.0 / kFreedAngleScale;
  extreme.x_mm = -131072.0;
  extreme.y_mm = 0x7FFFFF / kFreedPositionScale;
  extreme.z_mm = -1.0 / kFreedPositionScale;
  extreme.zoom = 0xFFFFFF;
  extreme.focus = 1;
  extreme.user = 0xFFFF;
  messages.push_back(extreme);
  for (const FreedD1 &m : messages) {
    const auto bytes = encode_freed_d1(m);
    const FreedParseResult r = parse_freed_d1(bytes);
    ASSERT_TRUE(r) << r.detail;
    EXPECT_EQ(*r.message, m);
    EXPECT_EQ(encode_freed_d1(*r.message), bytes);
  }
}

TEST(FreedD1, EncoderRoundsToNearestStep) {
  FreedD1 m;
  m.pan_deg = 10.0 + 0.4 / kFreedAngleScale;
  m.x_mm = -3.0 - 0.6 / kFreedPositionScale;
  const FreedParseResult r = parse_freed_d1(encode_freed_d1(m));
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.message->pan_deg, 10.0);
  EXPECT_EQ(r.message->x_mm, -3.0 - 1.0 / kFreedPositionScale);
}

TEST(FreedD1, EncoderSaturatesInsteadOfWrapping) {
  FreedD1 m;
  m.pan_deg = 1000.0;
  m.tilt_deg = -std::numeric_limits<double>::infinity();
  m.roll_deg = std::numeric_limits<double>::quiet_NaN();
  m.x_mm = 1e12;
  m.zoom = 0x12345678;
  m.focus = 0xFFFFFFFF;
  const FreedParseResult r = parse_freed_d1(encode_freed_d1(m));
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.message->pan_deg, 0x7FFFFF / kFreedAngleScale);
  EXPECT_EQ(r.message->tilt_deg, -256.0);
  EXPECT_EQ(r.message->roll_deg, 0.0);
  EXPECT_EQ(r.message->x_mm, 0x7FFFFF / kFreedPositionScale);
  EXPECT_EQ(r.message->zoom, 0xFFFFFFu);
  EXPECT_EQ(r.message->focus, 0xFFFFFFu);
}

TEST(FreedD1, RejectsEveryTruncationAndOverlongDatagram) {
  for (std::size_t n = 0; n < kKnown.size(); ++n) {
    const FreedParseResult r = parse_freed_d1(std::span(kKnown).first(n));
    EXPECT_FALSE(r) << n;
    EXPECT_EQ(r.error, FreedError::wrong_length) << n;
    EXPECT_NE(r.detail.find("got " + std::to_string(n)), std::string::npos) << r.detail;
  }
  std::vector<std::uint8_t> longer(kKnown.begin(), kKnown.end());
  longer.push_back(0);
  const FreedParseResult r = parse_freed_d1(longer);
  EXPECT_FALSE(r);
  EXPECT_EQ(r.error, FreedError::wrong_length);
}

TEST(FreedD1, RejectsOtherMessageTypesEvenWithValidChecksum) {
  auto bytes = kKnown;
  bytes[0] = 0xD0; // a FreeD "D0" position request
  bytes[28] = freed_checksum(std::span(bytes).first(28));
  const FreedParseResult r = parse_freed_d1(bytes);
  EXPECT_FALSE(r);
  EXPECT_EQ(r.error, FreedError::wrong_type);
  EXPECT_NE(r.detail.find("0xD0"), std::string::npos) << r.detail;
}

TEST(FreedD1, RejectsBadChecksum) {
  auto bytes = kKnown;
  bytes[28] = 0x65;
  const FreedParseResult r = parse_freed_d1(bytes);
  EXPECT_FALSE(r);
  EXPECT_EQ(r.error, FreedError::bad_checksum);
  EXPECT_NE(r.detail.find("0x65"), std::string::npos) << r.detail;
  EXPECT_NE(r.detail.find("0x64"), std::string::npos) << r.detail;
}

// A single flipped bit changes the byte sum by +-2^k, never a multiple of 256,
// so the D1 checksum catches every one; a flip in byte 0 is caught earlier as
// a different message type.
TEST(FreedD1, RejectsEverySingleBitFlip) {
  for (std::size_t byte = 0; byte < kKnown.size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      auto bytes = kKnown;
      bytes[byte] ^= static_cast<std::uint8_t>(1u << bit);
      const FreedParseResult r = parse_freed_d1(bytes);
      EXPECT_FALSE(r) << "byte " << byte << " bit " << bit;
      EXPECT_EQ(r.error, byte == 0 ? FreedError::wrong_type : FreedError::bad_checksum)
          << "byte " << byte << " bit " << bit;
    }
  }
}

TEST(FreedD1, ErrorNamesAreDistinct) {
  EXPECT_STREQ(to_string(FreedError::wrong_length), "wrong length");
  EXPECT_STREQ(to_string(FreedError::wrong_type), "wrong message type");
  EXPECT_STREQ(to_string(FreedError::bad_checksum), "bad checksum");
}

} // namespace
} // namespace camhead::hal::lens
