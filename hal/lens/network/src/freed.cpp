// FreeD D1 parsing and building. See freed.h for the layout.
#include "camhead/hal/lens/network/freed.h"

#include <cmath>
#include <string>
#include <utility>

namespace camhead::hal::lens {
namespace {

constexpr std::size_t kChecksumIndex = kFreedD1Size - 1;
constexpr std::int32_t kInt24Max = 0x7FFFFF;
constexpr std::int32_t kInt24Min = -0x800000;
constexpr std::uint32_t kUint24Max = 0xFFFFFF;

// Byte offsets of the fields, in the order of the published layout.
constexpr std::size_t kCameraId = 1;
constexpr std::size_t kPan = 2, kTilt = 5, kRoll = 8;
constexpr std::size_t kX = 11, kY = 14, kZ = 17;
constexpr std::size_t kZoom = 20, kFocus = 23, kUser = 26;

std::uint32_t read_u24(std::span<const std::uint8_t> b, std::size_t at) {
  return (std::uint32_t{b[at]} << 16) | (std::uint32_t{b[at + 1]} << 8) | std::uint32_t{b[at + 2]};
}

// Sign extension by subtraction rather than by shifting into the sign bit, so
// that no step depends on implementation-defined shifts.
std::int32_t read_s24(std::span<const std::uint8_t> b, std::size_t at) {
  const auto raw = static_cast<std::int32_t>(read_u24(b, at));
  return (raw & 0x800000) != 0 ? raw - 0x1000000 : raw;
}

void write_u24(std::array<std::uint8_t, kFreedD1Size> &b, std::size_t at, std::uint32_t v) {
  b[at] = static_cast<std::uint8_t>(v >> 16);
  b[at + 1] = static_cast<std::uint8_t>(v >> 8);
  b[at + 2] = static_cast<std::uint8_t>(v);
}

void write_s24(std::array<std::uint8_t, kFreedD1Size> &b, std::size_t at, std::int32_t v) {
  // Two's complement in 24 bits; the cast to uint32 is modular by definition.
  write_u24(b, at, static_cast<std::uint32_t>(v) & kUint24Max);
}

// Physical value -> 24-bit signed wire counts, saturating (see freed.h).
// The range test happens in double before any conversion to an integer, so an
// out-of-range value never reaches the undefined float->int conversion.
std::int32_t to_s24(double value, double scale) {
  const double scaled = std::nearbyint(value * scale);
  if (std::isnan(scaled)) {
    return 0;
  }
  if (scaled >= kInt24Max) {
    return kInt24Max;
  }
  if (scaled <= kInt24Min) {
    return kInt24Min;
  }
  return static_cast<std::int32_t>(scaled);
}

FreedParseResult reject(FreedError error, std::string detail) {
  return FreedParseResult{std::nullopt, error, std::move(detail)};
}

std::string hex_byte(unsigned value) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  return std::string{"0x"} + kDigits[(value >> 4) & 0xF] + kDigits[value & 0xF];
}

} // namespace

std::uint8_t freed_checksum(std::span<const std::uint8_t> bytes) {
  unsigned sum = 0;
  for (const std::uint8_t b : bytes) {
    sum += b;
  }
  return static_cast<std::uint8_t>((0x40u - sum) & 0xFFu);
}

FreedParseResult parse_freed_d1(std::span<const std::uint8_t> datagram) {
  // Length first: every later check indexes the datagram.
  if (datagram.size() != kFreedD1Size) {
    return reject(FreedError::wrong_length, "FreeD D1: expected " + std::to_string(kFreedD1Size) +
                                                " bytes, got " + std::to_string(datagram.size()));
  }
  // Type before checksum, so that another FreeD message type (D0, D2, ...) is
  // reported as such rather than as corruption.
  if (datagram[0] != kFreedD1Type) {
    return reject(FreedError::wrong_type,
                  "FreeD D1: message type " + hex_byte(datagram[0]) + ", expected 0xD1");
  }
  const std::uint8_t expected = freed_checksum(datagram.first(kChecksumIndex));
  if (datagram[kChecksumIndex] != expected) {
    return reject(FreedError::bad_checksum, "FreeD D1: checksum " +
                                                hex_byte(datagram[kChecksumIndex]) + ", computed " +
                                                hex_byte(expected));
  }

  FreedD1 m;
  m.camera_id = datagram[kCameraId];
  m.pan_deg = read_s24(datagram, kPan) / kFreedAngleScale;
  m.tilt_deg = read_s24(datagram, kTilt) / kFreedAngleScale;
  m.roll_deg = read_s24(datagram, kRoll) / kFreedAngleScale;
  m.x_mm = read_s24(datagram, kX) / kFreedPositionScale;
  m.y_mm = read_s24(datagram, kY) / kFreedPositionScale;
  m.z_mm = read_s24(datagram, kZ) / kFreedPositionScale;
  m.zoom = read_u24(datagram, kZoom);
  m.focus = read_u24(datagram, kFocus);
  m.user = static_cast<std::uint16_t>((datagram[kUser] << 8) | datagram[kUser + 1]);
  return FreedParseResult{m, FreedError::none, {}};
}

std::array<std::uint8_t, kFreedD1Size> encode_freed_d1(const FreedD1 &message) {
  std::array<std::uint8_t, kFreedD1Size> b{};
  b[0] = kFreedD1Type;
  b[kCameraId] = message.camera_id;
  write_s24(b, kPan, to_s24(message.pan_deg, kFreedAngleScale));
  write_s24(b, kTilt, to_s24(message.tilt_deg, kFreedAngleScale));
  write_s24(b, kRoll, to_s24(message.roll_deg, kFreedAngleScale));
  write_s24(b, kX, to_s24(message.x_mm, kFreedPositionScale));
  write_s24(b, kY, to_s24(message.y_mm, kFreedPositionScale));
  write_s24(b, kZ, to_s24(message.z_mm, kFreedPositionScale));
  write_u24(b, kZoom, message.zoom > kUint24Max ? kUint24Max : message.zoom);
  write_u24(b, kFocus, message.focus > kUint24Max ? kUint24Max : message.focus);
  b[kUser] = static_cast<std::uint8_t>(message.user >> 8);
  b[kUser + 1] = static_cast<std::uint8_t>(message.user);
  b[kChecksumIndex] = freed_checksum(std::span<const std::uint8_t>(b).first(kChecksumIndex));
  return b;
}

const char *to_string(FreedError error) {
  switch (error) {
  case FreedError::none:
    return "none";
  case FreedError::wrong_length:
    return "wrong length";
  case FreedError::wrong_type:
    return "wrong message type";
  case FreedError::bad_checksum:
    return "bad checksum";
  }
  return "unknown";
}

} // namespace camhead::hal::lens
