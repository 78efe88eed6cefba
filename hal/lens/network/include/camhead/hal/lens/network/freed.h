// FreeD "D1" camera-position messages: the 29-byte datagram that tracking
// heads, PTZ cameras and lens-encoder boxes send over UDP or RS-422.
//
// This header is parsing and building only: no sockets, no threads, no state,
// so every function here may be called from any thread. A receiver (a future
// hal/lens network source) owns the socket and turns a parsed message into
// encoder counts for lens_control.
//
// Layout (all multi-byte fields big-endian):
//
//   byte  0      message type, 0xD1
//   byte  1      camera id
//   bytes 2-10   pan, tilt, roll: 24-bit signed, degrees * 32768
//   bytes 11-19  X, Y, Z: 24-bit signed, millimetres * 64
//   bytes 20-22  zoom: 24-bit unsigned raw encoder counts
//   bytes 23-25  focus: 24-bit unsigned raw encoder counts
//   bytes 26-27  spare / user defined (16 bits)
//   byte  28     checksum = (0x40 - sum of bytes 0..27) mod 256
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace camhead::hal::lens {

inline constexpr std::size_t kFreedD1Size = 29;
inline constexpr std::uint8_t kFreedD1Type = 0xD1;

// Fixed-point scales of the wire format. Every wire value is an exact double
// after division by these powers of two, so parse -> encode is bit-exact.
inline constexpr double kFreedAngleScale = 32768.0; // counts per degree
inline constexpr double kFreedPositionScale = 64.0; // counts per millimetre

// One D1 message in physical units. Zoom and focus stay raw encoder counts:
// what they mean optically is the lens profile's business (lens_control), not
// the transport's.
struct FreedD1 {
  std::uint8_t camera_id = 0;
  double pan_deg = 0.0, tilt_deg = 0.0, roll_deg = 0.0;
  double x_mm = 0.0, y_mm = 0.0, z_mm = 0.0;
  std::uint32_t zoom = 0;  // 0 .. 0xFFFFFF
  std::uint32_t focus = 0; // 0 .. 0xFFFFFF
  std::uint16_t user = 0;

  bool operator==(const FreedD1 &) const = default;
};

// Why a datagram was rejected; tests and the receiver's statistics key on
// this, the text is for logs.
enum class FreedError {
  none,
  wrong_length,
  wrong_type,
  bad_checksum,
};

// GCC 12 has no std::expected: the message is set exactly when error is
// FreedError::none, and `detail` then is empty.
struct [[nodiscard]] FreedParseResult {
  std::optional<FreedD1> message;
  FreedError error = FreedError::none;
  std::string detail;

  explicit operator bool() const { return message.has_value(); }
};

// The D1 checksum over the first 28 bytes (or fewer, for tests): 0x40 minus
// the byte sum, modulo 256.
[[nodiscard]] std::uint8_t freed_checksum(std::span<const std::uint8_t> bytes);

// Validates length, type byte and checksum, then decodes. Never reads outside
// `datagram`, whatever its size.
[[nodiscard]] FreedParseResult parse_freed_d1(std::span<const std::uint8_t> datagram);

// Builds a valid D1 message. Values outside what 24 bits can carry (angles
// beyond +-256 degrees, positions beyond +-131 m, counts beyond 0xFFFFFF)
// saturate, NaN encodes as 0: a sender should clamp rather than wrap a pan
// into the opposite direction. Angles and positions round to the nearest
// wire step.
[[nodiscard]] std::array<std::uint8_t, kFreedD1Size> encode_freed_d1(const FreedD1 &message);

[[nodiscard]] const char *to_string(FreedError error);

} // namespace camhead::hal::lens
