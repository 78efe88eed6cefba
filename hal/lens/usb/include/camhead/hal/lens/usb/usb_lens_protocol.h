// The camhead USB lens-encoder protocol, version 1 (docs/usb-lens-protocol.md):
// the 28-byte report the board sends on its interrupt IN endpoint and the
// 16-byte answer to its one vendor request, GET_INFO.
//
// Parsing and building only: no libusb, no threads, no state, so every
// function here may be called from any thread, and the fuzz build compiles
// this without libusb. The host backend (usb_lens.h), the simulated board
// (simulated_usb_lens.h) and the VM test's FunctionFS gadget all go through
// these functions, so the three cannot disagree about a byte.
//
// Report layout (little-endian):
//
//   bytes  0-1   magic 0x4C43 ("CL")
//   byte   2     version, 1
//   byte   3     axes fitted: bit 0 focus, 1 iris, 2 zoom; bits 3-7 zero
//   bytes  4-7   sequence: +1 per latched sample, sent or not
//   bytes  8-11  device time, us, free-running, wraps at 2^32
//   bytes 12-23  focus, iris, zoom: int32 counts
//   bytes 24-25  status: bits 0-2 homed, bits 4-6 encoder fault, rest zero
//   bytes 26-27  CRC-16/CCITT-FALSE of bytes 0-25
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace camhead::hal::lens {

// pid.codes' vendor id and its shared TEST product id (1209:0001, "pid.codes
// Test PID"): for the lab only, never for a board that leaves it. A shipped
// board gets its own PID; this constant and the udev rule are all that change.
inline constexpr std::uint16_t kUsbLensVendorId = 0x1209;
inline constexpr std::uint16_t kUsbLensProductId = 0x0001;

// The interface that carries the protocol. The test PID is shared with every
// other lab project, so the host also requires these three numbers.
inline constexpr std::uint8_t kUsbLensInterfaceClass = 0xFF;    // vendor specific
inline constexpr std::uint8_t kUsbLensInterfaceSubClass = 0x4C; // 'L'
inline constexpr std::uint8_t kUsbLensInterfaceProtocol = 0x01; // report version 1

inline constexpr std::uint16_t kUsbLensMagic = 0x4C43; // bytes 43 4C, "CL"
inline constexpr std::uint8_t kUsbLensVersion = 1;
inline constexpr std::size_t kUsbLensReportSize = 28;

// Bits of LensReport::axes (and BoardInfo::axes).
inline constexpr std::uint8_t kAxisFocus = 0x01;
inline constexpr std::uint8_t kAxisIris = 0x02;
inline constexpr std::uint8_t kAxisZoom = 0x04;
inline constexpr std::uint8_t kAxesAll = kAxisFocus | kAxisIris | kAxisZoom;

// Bits of LensReport::status: homed (the count is absolute) and encoder
// fault (the count cannot be trusted), one per axis.
inline constexpr std::uint16_t kStatusFocusHomed = 0x0001;
inline constexpr std::uint16_t kStatusIrisHomed = 0x0002;
inline constexpr std::uint16_t kStatusZoomHomed = 0x0004;
inline constexpr std::uint16_t kStatusFocusFault = 0x0010;
inline constexpr std::uint16_t kStatusIrisFault = 0x0020;
inline constexpr std::uint16_t kStatusZoomFault = 0x0040;
inline constexpr std::uint16_t kStatusAllHomed =
    kStatusFocusHomed | kStatusIrisHomed | kStatusZoomHomed;
inline constexpr std::uint16_t kStatusDefinedBits =
    kStatusAllHomed | kStatusFocusFault | kStatusIrisFault | kStatusZoomFault;

// One report, field for field. Counts of an axis that is not fitted are
// carried as sent (the firmware sends 0), so parse -> encode is bit-exact.
struct LensReport {
  std::uint8_t axes = kAxesAll;
  std::uint32_t sequence = 0;
  std::uint32_t device_time_us = 0;
  std::int32_t focus = 0, iris = 0, zoom = 0;
  std::uint16_t status = kStatusAllHomed;

  bool operator==(const LensReport &) const = default;
};

// Why a report was rejected: the host's `malformed` counter keys on any of
// them, tests on each; the text is for logs.
enum class ReportError {
  none,
  wrong_length,
  bad_magic,
  bad_version,
  bad_checksum,
  reserved_bits, // a valid CRC, but a bit that version 1 leaves zero is set
};

// GCC 12 has no std::expected: `report` is set exactly when error is
// ReportError::none, and `detail` then is empty.
struct [[nodiscard]] ReportParseResult {
  std::optional<LensReport> report;
  ReportError error = ReportError::none;
  std::string detail;

  explicit operator bool() const { return report.has_value(); }
};

// CRC-16/CCITT-FALSE: polynomial 0x1021, init 0xFFFF, MSB first, no final
// XOR. "123456789" -> 0x29B1.
[[nodiscard]] std::uint16_t crc16_ccitt_false(std::span<const std::uint8_t> bytes);

// Length, magic, version, CRC, reserved bits, in that order. Never reads
// outside `bytes`, whatever its size. Allocates only to describe a rejection.
[[nodiscard]] ReportParseResult parse_report(std::span<const std::uint8_t> bytes);

// Builds a valid report (magic, version and CRC filled in). Reserved bits in
// `axes` and `status` are sent as given, so that tests can build reports the
// parser must reject; a firmware leaves them zero.
[[nodiscard]] std::array<std::uint8_t, kUsbLensReportSize> encode_report(const LensReport &report);

[[nodiscard]] const char *to_string(ReportError error);

// ---- GET_INFO -------------------------------------------------------------

// bmRequestType 0xC1 (IN, vendor, interface), bRequest 0x01, wValue 0,
// wIndex the interface number, wLength 16.
inline constexpr std::uint8_t kUsbLensGetInfoRequestType = 0xC1;
inline constexpr std::uint8_t kUsbLensGetInfoRequest = 0x01;
inline constexpr std::size_t kUsbLensInfoSize = 16;

struct BoardInfo {
  std::uint8_t axes = kAxesAll;
  std::uint32_t firmware_version = 0; // major << 16 | minor << 8 | patch
  std::uint32_t device_time_us = 0;
  std::uint16_t report_rate_hz = 0;

  bool operator==(const BoardInfo &) const = default;
};

struct [[nodiscard]] BoardInfoParseResult {
  std::optional<BoardInfo> info;
  ReportError error = ReportError::none;
  std::string detail;

  explicit operator bool() const { return info.has_value(); }
};

[[nodiscard]] BoardInfoParseResult parse_board_info(std::span<const std::uint8_t> bytes);
[[nodiscard]] std::array<std::uint8_t, kUsbLensInfoSize> encode_board_info(const BoardInfo &info);

// "1.2.3" from the packed firmware version.
[[nodiscard]] std::string firmware_version_string(std::uint32_t packed);

} // namespace camhead::hal::lens
