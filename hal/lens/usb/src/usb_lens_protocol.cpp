// USB lens-encoder report and GET_INFO parsing and building. See
// usb_lens_protocol.h for the layout and docs/usb-lens-protocol.md for why.
#include "camhead/hal/lens/usb/usb_lens_protocol.h"

#include <string>
#include <utility>

namespace camhead::hal::lens {
namespace {

// Byte offsets of the report fields, in the order of the published layout.
constexpr std::size_t kMagic = 0, kVersion = 2, kAxes = 3, kSequence = 4, kTime = 8;
constexpr std::size_t kFocus = 12, kIris = 16, kZoom = 20, kStatus = 24, kCrc = 26;
static_assert(kCrc + 2 == kUsbLensReportSize);

// GET_INFO offsets.
constexpr std::size_t kInfoFirmware = 4, kInfoTime = 8, kInfoRate = 12, kInfoCrc = 14;
static_assert(kInfoCrc + 2 == kUsbLensInfoSize);

constexpr std::uint8_t kAxesReserved = static_cast<std::uint8_t>(~kAxesAll);
constexpr std::uint16_t kStatusReserved = static_cast<std::uint16_t>(~kStatusDefinedBits);

std::uint16_t read_u16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}

std::uint32_t read_u32(std::span<const std::uint8_t> b, std::size_t at) {
  return std::uint32_t{b[at]} | (std::uint32_t{b[at + 1]} << 8) | (std::uint32_t{b[at + 2]} << 16) |
         (std::uint32_t{b[at + 3]} << 24);
}

// uint32 -> int32 is modular since C++20: two's complement by definition.
std::int32_t read_s32(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::int32_t>(read_u32(b, at));
}

void write_u16(std::span<std::uint8_t> b, std::size_t at, std::uint16_t v) {
  b[at] = static_cast<std::uint8_t>(v);
  b[at + 1] = static_cast<std::uint8_t>(v >> 8);
}

void write_u32(std::span<std::uint8_t> b, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) {
    b[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
  }
}

std::string hex(unsigned value, int digits) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s = "0x";
  for (int i = digits - 1; i >= 0; --i) {
    s += kDigits[(value >> (4 * i)) & 0xF];
  }
  return s;
}

// The checks both messages share, in the documented order: length, magic,
// version, CRC. Returns ReportError::none when the framing is sound.
std::pair<ReportError, std::string> check_frame(std::span<const std::uint8_t> bytes,
                                                std::size_t size, const char *what) {
  // Built only on a rejection: a good report allocates nothing.
  const auto prefix = [what] { return std::string{"usb lens "} + what + ": "; };
  if (bytes.size() != size) {
    return {ReportError::wrong_length, prefix() + "expected " + std::to_string(size) +
                                           " bytes, got " + std::to_string(bytes.size())};
  }
  const std::uint16_t magic = read_u16(bytes, kMagic);
  if (magic != kUsbLensMagic) {
    return {ReportError::bad_magic,
            prefix() + "magic " + hex(magic, 4) + ", expected " + hex(kUsbLensMagic, 4)};
  }
  if (bytes[kVersion] != kUsbLensVersion) {
    return {ReportError::bad_version, prefix() + "version " + std::to_string(bytes[kVersion]) +
                                          ", this host speaks version " +
                                          std::to_string(kUsbLensVersion)};
  }
  const std::uint16_t sent = read_u16(bytes, size - 2);
  const std::uint16_t computed = crc16_ccitt_false(bytes.first(size - 2));
  if (sent != computed) {
    return {ReportError::bad_checksum,
            prefix() + "CRC " + hex(sent, 4) + ", computed " + hex(computed, 4)};
  }
  return {ReportError::none, {}};
}

} // namespace

std::uint16_t crc16_ccitt_false(std::span<const std::uint8_t> bytes) {
  std::uint16_t crc = 0xFFFF;
  for (const std::uint8_t b : bytes) {
    crc = static_cast<std::uint16_t>(crc ^ (b << 8));
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x8000) != 0 ? static_cast<std::uint16_t>((crc << 1) ^ 0x1021)
                                : static_cast<std::uint16_t>(crc << 1);
    }
  }
  return crc;
}

ReportParseResult parse_report(std::span<const std::uint8_t> bytes) {
  auto [error, detail] = check_frame(bytes, kUsbLensReportSize, "report");
  if (error != ReportError::none) {
    return ReportParseResult{std::nullopt, error, std::move(detail)};
  }
  // Reserved bits last: with a valid CRC they are not corruption but a
  // sender that speaks a newer dialect under the old version number.
  const std::uint16_t status = read_u16(bytes, kStatus);
  if ((bytes[kAxes] & kAxesReserved) != 0 || (status & kStatusReserved) != 0) {
    return ReportParseResult{std::nullopt, ReportError::reserved_bits,
                             "usb lens report: reserved bits set (axes " + hex(bytes[kAxes], 2) +
                                 ", status " + hex(status, 4) + ")"};
  }
  LensReport r;
  r.axes = bytes[kAxes];
  r.sequence = read_u32(bytes, kSequence);
  r.device_time_us = read_u32(bytes, kTime);
  r.focus = read_s32(bytes, kFocus);
  r.iris = read_s32(bytes, kIris);
  r.zoom = read_s32(bytes, kZoom);
  r.status = status;
  return ReportParseResult{r, ReportError::none, {}};
}

std::array<std::uint8_t, kUsbLensReportSize> encode_report(const LensReport &report) {
  std::array<std::uint8_t, kUsbLensReportSize> b{};
  write_u16(b, kMagic, kUsbLensMagic);
  b[kVersion] = kUsbLensVersion;
  b[kAxes] = report.axes;
  write_u32(b, kSequence, report.sequence);
  write_u32(b, kTime, report.device_time_us);
  write_u32(b, kFocus, static_cast<std::uint32_t>(report.focus));
  write_u32(b, kIris, static_cast<std::uint32_t>(report.iris));
  write_u32(b, kZoom, static_cast<std::uint32_t>(report.zoom));
  write_u16(b, kStatus, report.status);
  write_u16(b, kCrc, crc16_ccitt_false(std::span<const std::uint8_t>(b).first(kCrc)));
  return b;
}

BoardInfoParseResult parse_board_info(std::span<const std::uint8_t> bytes) {
  auto [error, detail] = check_frame(bytes, kUsbLensInfoSize, "GET_INFO");
  if (error != ReportError::none) {
    return BoardInfoParseResult{std::nullopt, error, std::move(detail)};
  }
  if ((bytes[kAxes] & kAxesReserved) != 0) {
    return BoardInfoParseResult{std::nullopt, ReportError::reserved_bits,
                                "usb lens GET_INFO: reserved axes bits set (" +
                                    hex(bytes[kAxes], 2) + ")"};
  }
  BoardInfo info;
  info.axes = bytes[kAxes];
  info.firmware_version = read_u32(bytes, kInfoFirmware);
  info.device_time_us = read_u32(bytes, kInfoTime);
  info.report_rate_hz = read_u16(bytes, kInfoRate);
  return BoardInfoParseResult{info, ReportError::none, {}};
}

std::array<std::uint8_t, kUsbLensInfoSize> encode_board_info(const BoardInfo &info) {
  std::array<std::uint8_t, kUsbLensInfoSize> b{};
  write_u16(b, kMagic, kUsbLensMagic);
  b[kVersion] = kUsbLensVersion;
  b[kAxes] = info.axes;
  write_u32(b, kInfoFirmware, info.firmware_version);
  write_u32(b, kInfoTime, info.device_time_us);
  write_u16(b, kInfoRate, info.report_rate_hz);
  write_u16(b, kInfoCrc, crc16_ccitt_false(std::span<const std::uint8_t>(b).first(kInfoCrc)));
  return b;
}

std::string firmware_version_string(std::uint32_t packed) {
  return std::to_string((packed >> 16) & 0xFFFF) + "." + std::to_string((packed >> 8) & 0xFF) +
         "." + std::to_string(packed & 0xFF);
}

const char *to_string(ReportError error) {
  switch (error) {
  case ReportError::none:
    return "none";
  case ReportError::wrong_length:
    return "wrong length";
  case ReportError::bad_magic:
    return "bad magic";
  case ReportError::bad_version:
    return "unsupported version";
  case ReportError::bad_checksum:
    return "bad checksum";
  case ReportError::reserved_bits:
    return "reserved bits set";
  }
  return "unknown";
}

} // namespace camhead::hal::lens
