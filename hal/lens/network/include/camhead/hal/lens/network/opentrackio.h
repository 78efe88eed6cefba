// OpenTrackIO (SMPTE RIS) lens data: one JSON sample per UDP datagram
// (default port 55555), behind a 16-byte binary header.
//
// Parsing and building only: no sockets, no threads, no state, so every
// function here may be called from any thread. The JSON library stays inside
// the .cpp; this header exposes plain types only.
//
// Header layout as implemented (multi-byte fields big-endian). It follows the
// task brief and agrees with the header of Epic's LiveLink OpenTrackIO
// receiver; it has NOT been checked against the SMPTE RIS document itself:
//
//   bytes 0-3    ASCII "OTrk"
//   byte  4      reserved: written as 0, ignored on receipt
//   byte  5      payload encoding: 0x01 JSON, 0x02 CBOR (only JSON accepted)
//   bytes 6-7    sequence number (uint16)
//   bytes 8-11   segment offset (uint32), 0 for a single-segment payload
//   bytes 12-13  bit 15: last-segment flag; bits 0-14: payload length
//   bytes 14-15  Fletcher-16 (mod 255) over bytes 0-13 and the payload,
//                stored as (sum2 << 8) | sum1
//
// Only single-segment samples are accepted (flag set, offset 0): lens samples
// are a few hundred bytes, far below any MTU, and reassembly needs state that
// a pure parser cannot keep.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "camhead/hal/lens/lens_encoder.h"

namespace camhead::hal::lens {

inline constexpr std::size_t kOpenTrackIoHeaderSize = 16;
inline constexpr std::size_t kOpenTrackIoMaxPayload = 0x7FFF; // 15-bit length field
inline constexpr std::uint16_t kOpenTrackIoPort = 55555;
inline constexpr std::uint8_t kOpenTrackIoJson = 0x01;
inline constexpr std::uint8_t kOpenTrackIoCbor = 0x02;

// timing.sampleTimestamp: PTP-style seconds and nanoseconds.
struct OpenTrackIoTimestamp {
  std::uint64_t seconds = 0;
  std::uint32_t nanoseconds = 0; // < 1e9

  bool operator==(const OpenTrackIoTimestamp &) const = default;
};

// One entry of a sample's `transforms`: translation (metres) and rotation
// (pan, tilt, roll in degrees) of a frame relative to the one before it in
// the list; the first is relative to the stage's origin. `scale` is read as
// 1 (camhead tracks cameras, which do not scale).
//
// Axes, as camdkit describes OpenTrackIO 1.0 (not checked against the SMPTE
// document itself): right-handed, Z up, Y forward and X right when pan, tilt
// and roll are 0; rotations intrinsic about Z, X, Y in that order (pan, then
// tilt, then roll), each positive by the right-hand rule: a positive pan turns
// the camera to the left, a positive tilt up, a positive roll clockwise as
// seen from behind the camera.
struct OpenTrackIoTransform {
  TrackedPose pose;
  std::optional<std::string> id = std::nullopt;

  bool operator==(const OpenTrackIoTransform &) const = default;
};

// What camhead reads of one sample: the lens, the transforms and the timing.
// Every field the sender left out is empty; a sample with no `lens` object at
// all parses to all-empty lens fields (a tracker-only sample is valid).
struct OpenTrackIoSample {
  std::uint16_t header_sequence = 0; // from the binary header, for loss counting

  std::optional<double> focus_distance_m;        // lens.focusDistance, > 0
  std::optional<double> f_stop;                  // lens.fStop, > 0
  std::optional<double> pinhole_focal_length_mm; // lens.pinholeFocalLength, > 0

  // lens.encoders, normalised to [0, 1]; focus 0 is infinity.
  std::optional<double> encoder_focus, encoder_iris, encoder_zoom;

  std::optional<std::uint64_t> sample_sequence;         // timing.sequenceNumber
  std::optional<OpenTrackIoTimestamp> sample_timestamp; // timing.sampleTimestamp
  std::optional<std::string> sample_id;                 // sampleId, e.g. "urn:uuid:..."

  std::vector<OpenTrackIoTransform> transforms; // in the sample's order

  bool operator==(const OpenTrackIoSample &) const = default;
};

// Why a datagram was rejected; tests and a receiver's statistics key on this,
// `detail` names the field for logs.
enum class OpenTrackIoError {
  none,
  truncated,            // shorter than the 16-byte header
  bad_magic,            // not "OTrk"
  length_mismatch,      // header payload length != bytes after the header
  bad_checksum,         // Fletcher-16 mismatch
  unsupported_encoding, // CBOR or an unknown/vendor encoding
  multi_segment,        // last-segment flag clear or non-zero segment offset
  malformed_json,       // payload is not one JSON document
  wrong_type,           // a field has the wrong JSON type
  out_of_range,         // a number outside its allowed range
  non_finite,           // a number that overflowed to +-infinity
};

// GCC 12 has no std::expected: sample is set exactly when error is
// OpenTrackIoError::none, and `detail` then is empty.
struct [[nodiscard]] OpenTrackIoParseResult {
  std::optional<OpenTrackIoSample> sample;
  OpenTrackIoError error = OpenTrackIoError::none;
  std::string detail;

  explicit operator bool() const { return sample.has_value(); }
};

// Fletcher-16 with modulus 255 over the concatenation of `first` and
// `second`, returned as (sum2 << 8) | sum1.
[[nodiscard]] std::uint16_t fletcher16(std::span<const std::uint8_t> first,
                                       std::span<const std::uint8_t> second = {});

// Validates the header and the JSON payload and extracts the fields above.
// Never throws and never reads outside `datagram`.
[[nodiscard]] OpenTrackIoParseResult parse_opentrackio(std::span<const std::uint8_t> datagram);

// Wraps an already-serialised payload in a single-segment header with a valid
// checksum. Empty when the payload exceeds kOpenTrackIoMaxPayload. Tests use
// it to send arbitrary (also broken) JSON behind a correct header.
[[nodiscard]] std::vector<std::uint8_t>
encode_opentrackio_datagram(std::span<const std::uint8_t> payload, std::uint16_t sequence,
                            std::uint8_t encoding = kOpenTrackIoJson);

// Builds a JSON sample with the fields of `sample` that are set (plus the
// protocol name and version) and wraps it with sample.header_sequence. Fields
// should be finite: the JSON writer turns NaN and infinity into null, which
// the parser then rejects. Empty when the sample does not fit one datagram.
[[nodiscard]] std::vector<std::uint8_t> encode_opentrackio(const OpenTrackIoSample &sample);

// The camera's pose relative to the stage: the transforms composed in order
// (each relative to the one before), in OpenTrackIO's axes and angles; empty
// for a sample without transforms.
[[nodiscard]] std::optional<TrackedPose>
opentrackio_camera_pose(std::span<const OpenTrackIoTransform> transforms);

[[nodiscard]] const char *to_string(OpenTrackIoError error);

} // namespace camhead::hal::lens
