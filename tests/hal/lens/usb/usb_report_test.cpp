// The lens board's report and GET_INFO answer: hand-assembled bytes from
// docs/usb-lens-protocol.md, the CRC's published check value, round trips,
// and every truncation and single-bit error a USB link or a buggy firmware
// can deliver.
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "camhead/hal/lens/usb/usb_lens_protocol.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

// The worked example of the protocol document, assembled by hand:
//   magic 0x4C43 -> 43 4C, version 1, axes 0x07,
//   sequence 258 = 0x00000102, device time 1234567 = 0x0012D687,
//   focus 4660 = 0x1234, iris -100 = 0xFFFFFF9C, zoom 70000 = 0x00011170,
//   status 0x0007 (all homed), CRC-16/CCITT-FALSE of bytes 0-25 = 0xBBBF.
constexpr std::array<std::uint8_t, kUsbLensReportSize> kKnown = {
    0x43, 0x4C, 0x01, 0x07, // magic, version, axes
    0x02, 0x01, 0x00, 0x00, // sequence
    0x87, 0xD6, 0x12, 0x00, // device time
    0x34, 0x12, 0x00, 0x00, // focus
    0x9C, 0xFF, 0xFF, 0xFF, // iris
    0x70, 0x11, 0x01, 0x00, // zoom
    0x07, 0x00,             // status
    0xBF, 0xBB,             // CRC
};

LensReport known_report() {
  LensReport r;
  r.axes = kAxesAll;
  r.sequence = 258;
  r.device_time_us = 1'234'567;
  r.focus = 4660;
  r.iris = -100;
  r.zoom = 70000;
  r.status = kStatusAllHomed;
  return r;
}

// GET_INFO example of the document: firmware 1.2.3, 500 Hz, same time, CRC 0x9E0F.
constexpr std::array<std::uint8_t, kUsbLensInfoSize> kKnownInfo = {
    0x43, 0x4C, 0x01, 0x07, 0x03, 0x02, 0x01, 0x00, 0x87, 0xD6, 0x12, 0x00, 0xF4, 0x01, 0x0F, 0x9E,
};

std::span<const std::uint8_t> bytes_of(const std::string &s) {
  return {reinterpret_cast<const std::uint8_t *>(s.data()), s.size()};
}

TEST(UsbLensCrc, MatchesPublishedCheckValue) {
  // CRC-16/CCITT-FALSE (CRC-16/IBM-3740) check value from the CRC catalogue.
  EXPECT_EQ(crc16_ccitt_false(bytes_of("123456789")), 0x29B1);
  EXPECT_EQ(crc16_ccitt_false({}), 0xFFFF); // the initial value, untouched
}

TEST(UsbLensReport, ParsesHandAssembledReport) {
  const ReportParseResult r = parse_report(kKnown);
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(r.error, ReportError::none);
  EXPECT_TRUE(r.detail.empty());
  EXPECT_EQ(*r.report, known_report());
}

TEST(UsbLensReport, EncoderReproducesHandAssembledReport) {
  EXPECT_EQ(encode_report(known_report()), kKnown);
}

TEST(UsbLensReport, RoundTripsExtremes) {
  LensReport r;
  r.axes = 0;
  r.sequence = 0xFFFFFFFF;
  r.device_time_us = 0xFFFFFFFF;
  r.focus = std::numeric_limits<std::int32_t>::min();
  r.iris = std::numeric_limits<std::int32_t>::max();
  r.zoom = -1;
  r.status = kStatusDefinedBits;
  const ReportParseResult parsed = parse_report(encode_report(r));
  ASSERT_TRUE(parsed) << parsed.detail;
  EXPECT_EQ(*parsed.report, r);
}

TEST(UsbLensReport, RejectsEveryTruncationAndExtension) {
  for (std::size_t n = 0; n < kUsbLensReportSize; ++n) {
    const ReportParseResult r = parse_report(std::span(kKnown).first(n));
    EXPECT_FALSE(r) << n << " bytes";
    EXPECT_EQ(r.error, ReportError::wrong_length) << n << " bytes";
    EXPECT_NE(r.detail.find("got " + std::to_string(n)), std::string::npos) << r.detail;
  }
  // A full-speed packet's worth (a firmware that pads) and one byte too many.
  for (const std::size_t n : {kUsbLensReportSize + 1, std::size_t{64}}) {
    std::vector<std::uint8_t> longer(kKnown.begin(), kKnown.end());
    longer.resize(n, 0);
    EXPECT_EQ(parse_report(longer).error, ReportError::wrong_length) << n << " bytes";
  }
}

TEST(UsbLensReport, RejectsEverySingleBitFlip) {
  for (std::size_t bit = 0; bit < kUsbLensReportSize * 8; ++bit) {
    auto bytes = kKnown;
    bytes[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    const ReportParseResult r = parse_report(bytes);
    EXPECT_FALSE(r) << "bit " << bit;
    // Framing fields say what they are; everything else is the CRC's catch.
    const ReportError expected = bit < 16   ? ReportError::bad_magic
                                 : bit < 24 ? ReportError::bad_version
                                            : ReportError::bad_checksum;
    EXPECT_EQ(r.error, expected) << "bit " << bit << ": " << r.detail;
  }
}

TEST(UsbLensReport, RejectsReservedBitsEvenWithAValidCrc) {
  const auto with = [](std::uint8_t axes, std::uint16_t status) {
    LensReport r = known_report();
    r.axes = axes;
    r.status = status;
    return parse_report(encode_report(r));
  };
  for (int bit = 3; bit < 8; ++bit) {
    EXPECT_EQ(with(static_cast<std::uint8_t>(kAxesAll | (1 << bit)), kStatusAllHomed).error,
              ReportError::reserved_bits)
        << "axes bit " << bit;
  }
  for (int bit = 0; bit < 16; ++bit) {
    const auto status = static_cast<std::uint16_t>(1u << bit);
    const ReportParseResult r = with(kAxesAll, status);
    if ((status & kStatusDefinedBits) != 0) {
      EXPECT_TRUE(r) << "status bit " << bit << ": " << r.detail;
    } else {
      EXPECT_EQ(r.error, ReportError::reserved_bits) << "status bit " << bit;
    }
  }
}

TEST(UsbLensReport, DetailsNameWhatIsWrong) {
  auto bytes = kKnown;
  bytes[12] ^= 0x01;
  EXPECT_EQ(parse_report(bytes).detail, "usb lens report: CRC 0xBBBF, computed 0xC0DE");

  bytes = kKnown;
  bytes[2] = 2;
  EXPECT_EQ(parse_report(bytes).detail, "usb lens report: version 2, this host speaks version 1");
  bytes = kKnown;
  bytes[0] = 0;
  EXPECT_EQ(parse_report(bytes).detail, "usb lens report: magic 0x4C00, expected 0x4C43");
}

TEST(UsbLensReport, ErrorNames) {
  EXPECT_STREQ(to_string(ReportError::none), "none");
  EXPECT_STREQ(to_string(ReportError::wrong_length), "wrong length");
  EXPECT_STREQ(to_string(ReportError::bad_magic), "bad magic");
  EXPECT_STREQ(to_string(ReportError::bad_version), "unsupported version");
  EXPECT_STREQ(to_string(ReportError::bad_checksum), "bad checksum");
  EXPECT_STREQ(to_string(ReportError::reserved_bits), "reserved bits set");
}

TEST(UsbLensBoardInfo, ParsesAndReproducesHandAssembledAnswer) {
  BoardInfo expected;
  expected.axes = kAxesAll;
  expected.firmware_version = 0x010203;
  expected.device_time_us = 1'234'567;
  expected.report_rate_hz = 500;
  const BoardInfoParseResult r = parse_board_info(kKnownInfo);
  ASSERT_TRUE(r) << r.detail;
  EXPECT_EQ(*r.info, expected);
  EXPECT_EQ(encode_board_info(expected), kKnownInfo);
  EXPECT_EQ(firmware_version_string(expected.firmware_version), "1.2.3");
}

TEST(UsbLensBoardInfo, RejectsTruncationsAndBitFlips) {
  for (std::size_t n = 0; n < kUsbLensInfoSize; ++n) {
    EXPECT_EQ(parse_board_info(std::span(kKnownInfo).first(n)).error, ReportError::wrong_length);
  }
  for (std::size_t bit = 0; bit < kUsbLensInfoSize * 8; ++bit) {
    auto bytes = kKnownInfo;
    bytes[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    EXPECT_FALSE(parse_board_info(bytes)) << "bit " << bit;
  }
  BoardInfo reserved;
  reserved.axes = 0x80;
  EXPECT_EQ(parse_board_info(encode_board_info(reserved)).error, ReportError::reserved_bits);
}

} // namespace
} // namespace camhead::hal::lens
