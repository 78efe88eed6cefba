// OpenTrackIO header validation and lens-field extraction. See opentrackio.h
// for the header layout and what is accepted.
#include "camhead/hal/lens/network/opentrackio.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "json_error.h"

namespace camhead::hal::lens {
namespace {

using nlohmann::json;

constexpr std::uint8_t kMagic[4] = {'O', 'T', 'r', 'k'};
constexpr std::size_t kEncoding = 5, kSequence = 6, kOffset = 8, kLength = 12, kChecksum = 14;
constexpr std::uint16_t kLastSegmentFlag = 0x8000;
constexpr std::uint64_t kNanosPerSecond = 1'000'000'000;
constexpr std::uint64_t kNoLimit = std::numeric_limits<std::uint64_t>::max();

std::uint16_t read_u16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
}

std::uint32_t read_u32(std::span<const std::uint8_t> b, std::size_t at) {
  return (std::uint32_t{b[at]} << 24) | (std::uint32_t{b[at + 1]} << 16) |
         (std::uint32_t{b[at + 2]} << 8) | std::uint32_t{b[at + 3]};
}

void write_u16(std::vector<std::uint8_t> &b, std::size_t at, std::uint16_t v) {
  b[at] = static_cast<std::uint8_t>(v >> 8);
  b[at + 1] = static_cast<std::uint8_t>(v);
}

std::string hex16(std::uint16_t v) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string out = "0x";
  for (int shift = 12; shift >= 0; shift -= 4) {
    out += kDigits[(v >> shift) & 0xF];
  }
  return out;
}

OpenTrackIoParseResult reject(OpenTrackIoError error, std::string detail) {
  return OpenTrackIoParseResult{std::nullopt, error, std::move(detail)};
}

enum class Range { any, positive, unit };

// Typed access to optional fields. The first failure sticks and every later
// call is a no-op, so extraction reads as a straight list of fields.
class Fields {
public:
  // The child object `key` of `parent`, or nullptr when absent or invalid.
  const json *object(const json &parent, const char *key, const std::string &path) {
    const json *child = find(parent, key);
    if (child != nullptr && !child->is_object()) {
      fail(OpenTrackIoError::wrong_type, path + ": expected an object, got " + child->type_name());
      return nullptr;
    }
    return child;
  }

  // A finite number, > 0 for `positive` and within [0, 1] for `unit`.
  std::optional<double> number(const json &parent, const char *key, const std::string &path,
                               Range range) {
    const json *child = find(parent, key);
    if (child == nullptr) {
      return std::nullopt;
    }
    if (!child->is_number()) {
      fail(OpenTrackIoError::wrong_type, path + ": expected a number, got " + child->type_name());
      return std::nullopt;
    }
    const double v = child->get<double>();
    if (!std::isfinite(v)) { // unreachable from JSON text, kept for a future CBOR path
      fail(OpenTrackIoError::non_finite, path + ": not a finite number");
      return std::nullopt;
    }
    const bool in_range = range == Range::any        ? true
                          : range == Range::positive ? v > 0.0
                                                     : (v >= 0.0 && v <= 1.0);
    if (!in_range) {
      fail(OpenTrackIoError::out_of_range,
           path + ": " + child->dump() +
               (range == Range::positive ? " must be > 0" : " must be within [0, 1]"));
      return std::nullopt;
    }
    return v;
  }

  // A non-negative JSON integer no larger than `max`.
  std::optional<std::uint64_t> count(const json &parent, const char *key, const std::string &path,
                                     std::uint64_t max) {
    const json *child = find(parent, key);
    if (child == nullptr) {
      return std::nullopt;
    }
    if (child->is_number_integer() && !child->is_number_unsigned()) {
      fail(OpenTrackIoError::out_of_range, path + ": " + child->dump() + " is negative");
      return std::nullopt;
    }
    if (!child->is_number_unsigned()) {
      fail(OpenTrackIoError::wrong_type,
           path + ": expected a non-negative integer, got " + child->type_name());
      return std::nullopt;
    }
    const auto v = child->get<std::uint64_t>();
    if (v > max) {
      fail(OpenTrackIoError::out_of_range,
           path + ": " + child->dump() + " exceeds " + std::to_string(max));
      return std::nullopt;
    }
    return v;
  }

  // A number that must be there.
  double required(const json &parent, const char *key, const std::string &path) {
    const std::optional<double> v = number(parent, key, path, Range::any);
    if (!v && ok()) {
      fail(OpenTrackIoError::wrong_type, path + ": missing");
    }
    return v.value_or(0.0);
  }

  // The child array `key` of `parent`, or nullptr when absent or invalid.
  const json *array(const json &parent, const char *key, const std::string &path) {
    const json *child = find(parent, key);
    if (child != nullptr && !child->is_array()) {
      fail(OpenTrackIoError::wrong_type, path + ": expected an array, got " + child->type_name());
      return nullptr;
    }
    return child;
  }

  std::optional<std::string> text(const json &parent, const char *key, const std::string &path) {
    const json *child = find(parent, key);
    if (child == nullptr) {
      return std::nullopt;
    }
    if (!child->is_string()) {
      fail(OpenTrackIoError::wrong_type, path + ": expected a string, got " + child->type_name());
      return std::nullopt;
    }
    return child->get<std::string>();
  }

  void fail(OpenTrackIoError error, std::string detail) {
    if (error_ == OpenTrackIoError::none) {
      error_ = error;
      detail_ = std::move(detail);
    }
  }

  [[nodiscard]] bool ok() const { return error_ == OpenTrackIoError::none; }
  [[nodiscard]] OpenTrackIoParseResult failure() const { return reject(error_, detail_); }

private:
  const json *find(const json &parent, const char *key) const {
    if (!ok()) {
      return nullptr;
    }
    const auto it = parent.find(key);
    return it == parent.end() ? nullptr : &*it;
  }

  OpenTrackIoError error_ = OpenTrackIoError::none;
  std::string detail_;
};

OpenTrackIoParseResult extract(const json &sample, std::uint16_t header_sequence) {
  if (!sample.is_object()) {
    return reject(OpenTrackIoError::wrong_type,
                  std::string{"sample: expected an object, got "} + sample.type_name());
  }
  OpenTrackIoSample out;
  out.header_sequence = header_sequence;
  Fields f;
  out.sample_id = f.text(sample, "sampleId", "sampleId");
  if (const json *timing = f.object(sample, "timing", "timing")) {
    out.sample_sequence = f.count(*timing, "sequenceNumber", "timing.sequenceNumber", kNoLimit);
    if (const json *ts = f.object(*timing, "sampleTimestamp", "timing.sampleTimestamp")) {
      const auto s = f.count(*ts, "seconds", "timing.sampleTimestamp.seconds", kNoLimit);
      const auto ns =
          f.count(*ts, "nanoseconds", "timing.sampleTimestamp.nanoseconds", kNanosPerSecond - 1);
      if (f.ok() && (!s || !ns)) {
        f.fail(OpenTrackIoError::wrong_type, std::string{"timing.sampleTimestamp."} +
                                                 (s ? "nanoseconds" : "seconds") + ": missing");
      }
      if (s && ns) {
        out.sample_timestamp = OpenTrackIoTimestamp{*s, static_cast<std::uint32_t>(*ns)};
      }
    }
  }
  if (const json *lens = f.object(sample, "lens", "lens")) {
    out.focus_distance_m = f.number(*lens, "focusDistance", "lens.focusDistance", Range::positive);
    out.f_stop = f.number(*lens, "fStop", "lens.fStop", Range::positive);
    out.pinhole_focal_length_mm =
        f.number(*lens, "pinholeFocalLength", "lens.pinholeFocalLength", Range::positive);
    if (const json *enc = f.object(*lens, "encoders", "lens.encoders")) {
      out.encoder_focus = f.number(*enc, "focus", "lens.encoders.focus", Range::unit);
      out.encoder_iris = f.number(*enc, "iris", "lens.encoders.iris", Range::unit);
      out.encoder_zoom = f.number(*enc, "zoom", "lens.encoders.zoom", Range::unit);
    }
  }
  if (const json *transforms = f.array(sample, "transforms", "transforms")) {
    out.transforms.reserve(transforms->size());
    for (std::size_t i = 0; i < transforms->size() && f.ok(); ++i) {
      const std::string path = "transforms[" + std::to_string(i) + "]";
      const json &entry = (*transforms)[i];
      if (!entry.is_object()) {
        f.fail(OpenTrackIoError::wrong_type,
               path + ": expected an object, got " + entry.type_name());
        break;
      }
      OpenTrackIoTransform &t = out.transforms.emplace_back();
      t.id = f.text(entry, "id", path + ".id");
      const json *translation = f.object(entry, "translation", path + ".translation");
      const json *rotation = f.object(entry, "rotation", path + ".rotation");
      if (f.ok() && (translation == nullptr || rotation == nullptr)) {
        f.fail(OpenTrackIoError::wrong_type,
               path + (translation == nullptr ? ".translation" : ".rotation") + ": missing");
        break;
      }
      if (!f.ok()) {
        break;
      }
      t.pose.x_m = f.required(*translation, "x", path + ".translation.x");
      t.pose.y_m = f.required(*translation, "y", path + ".translation.y");
      t.pose.z_m = f.required(*translation, "z", path + ".translation.z");
      t.pose.pan_deg = f.required(*rotation, "pan", path + ".rotation.pan");
      t.pose.tilt_deg = f.required(*rotation, "tilt", path + ".rotation.tilt");
      t.pose.roll_deg = f.required(*rotation, "roll", path + ".rotation.roll");
    }
  }
  if (!f.ok()) {
    return f.failure();
  }
  return OpenTrackIoParseResult{std::move(out), OpenTrackIoError::none, {}};
}

// Rotation matrices in OpenTrackIO's axes (X right, Y forward, Z up),
// row-major; the columns are the camera's right, forward and up.
using Matrix = std::array<double, 9>;
constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;

Matrix multiply(const Matrix &a, const Matrix &b) {
  Matrix m{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 3; ++k) {
        m[r * 3 + c] += a[r * 3 + k] * b[k * 3 + c];
      }
    }
  }
  return m;
}

// Rz(pan) Rx(tilt) Ry(roll): intrinsic Z, X, Y, right-handed.
Matrix rotation(const TrackedPose &p) {
  const double cp = std::cos(p.pan_deg * kRadiansPerDegree);
  const double sp = std::sin(p.pan_deg * kRadiansPerDegree);
  const double ct = std::cos(p.tilt_deg * kRadiansPerDegree);
  const double st = std::sin(p.tilt_deg * kRadiansPerDegree);
  const double cr = std::cos(p.roll_deg * kRadiansPerDegree);
  const double sr = std::sin(p.roll_deg * kRadiansPerDegree);
  const Matrix pan{cp, -sp, 0, sp, cp, 0, 0, 0, 1};
  const Matrix tilt{1, 0, 0, 0, ct, -st, 0, st, ct};
  const Matrix roll{cr, 0, sr, 0, 1, 0, -sr, 0, cr};
  return multiply(multiply(pan, tilt), roll);
}

} // namespace

std::optional<TrackedPose>
opentrackio_camera_pose(std::span<const OpenTrackIoTransform> transforms) {
  if (transforms.empty()) {
    return std::nullopt;
  }
  if (transforms.size() == 1) {
    return transforms.front().pose; // as sent, not through a matrix's rounding
  }
  Matrix r{1, 0, 0, 0, 1, 0, 0, 0, 1};
  double t[3] = {0.0, 0.0, 0.0};
  for (const OpenTrackIoTransform &transform : transforms) {
    const TrackedPose &p = transform.pose;
    const double local[3] = {p.x_m, p.y_m, p.z_m};
    for (int row = 0; row < 3; ++row) {
      t[row] += r[row * 3] * local[0] + r[row * 3 + 1] * local[1] + r[row * 3 + 2] * local[2];
    }
    r = multiply(r, rotation(p));
  }
  // Back to angles: the forward column is (-sin pan cos tilt, cos pan cos tilt,
  // sin tilt), the bottom row (-cos tilt sin roll, sin tilt, cos tilt cos roll).
  TrackedPose out;
  out.x_m = t[0];
  out.y_m = t[1];
  out.z_m = t[2];
  out.tilt_deg = std::asin(std::clamp(r[7], -1.0, 1.0)) / kRadiansPerDegree;
  out.pan_deg = std::atan2(-r[1], r[4]) / kRadiansPerDegree;
  out.roll_deg = std::atan2(-r[6], r[8]) / kRadiansPerDegree;
  return out;
}

std::uint16_t fletcher16(std::span<const std::uint8_t> first,
                         std::span<const std::uint8_t> second) {
  // Reduced every byte: payloads are at most 32 KiB, so clarity beats the
  // deferred-modulo trick.
  unsigned sum1 = 0, sum2 = 0;
  for (const auto part : {first, second}) {
    for (const std::uint8_t b : part) {
      sum1 = (sum1 + b) % 255;
      sum2 = (sum2 + sum1) % 255;
    }
  }
  return static_cast<std::uint16_t>((sum2 << 8) | sum1);
}

OpenTrackIoParseResult parse_opentrackio(std::span<const std::uint8_t> datagram) {
  if (datagram.size() < kOpenTrackIoHeaderSize) {
    return reject(OpenTrackIoError::truncated, "header: " + std::to_string(datagram.size()) +
                                                   " bytes, shorter than the 16-byte header");
  }
  if (!std::equal(std::begin(kMagic), std::end(kMagic), datagram.begin())) {
    return reject(OpenTrackIoError::bad_magic, "header: identifier is not \"OTrk\"");
  }
  const std::uint16_t length_field = read_u16(datagram, kLength);
  const std::size_t payload_size = length_field & kOpenTrackIoMaxPayload;
  const auto payload = datagram.subspan(kOpenTrackIoHeaderSize);
  if (payload.size() != payload_size) {
    return reject(OpenTrackIoError::length_mismatch,
                  "header: payload length " + std::to_string(payload_size) + ", datagram carries " +
                      std::to_string(payload.size()));
  }
  // Checksum before the encoding and segment checks, so that a corrupted
  // header is reported as corruption rather than as an unsupported feature.
  const std::uint16_t stored = read_u16(datagram, kChecksum);
  const std::uint16_t computed = fletcher16(datagram.first(kChecksum), payload);
  if (stored != computed) {
    return reject(OpenTrackIoError::bad_checksum,
                  "header: checksum " + hex16(stored) + ", computed " + hex16(computed));
  }
  const std::uint8_t encoding = datagram[kEncoding];
  if (encoding == kOpenTrackIoCbor) {
    return reject(OpenTrackIoError::unsupported_encoding,
                  "header: CBOR payloads are not supported; set the sender to JSON");
  }
  if (encoding != kOpenTrackIoJson) {
    return reject(OpenTrackIoError::unsupported_encoding,
                  "header: unknown payload encoding " + std::to_string(encoding));
  }
  if ((length_field & kLastSegmentFlag) == 0 || read_u32(datagram, kOffset) != 0) {
    return reject(OpenTrackIoError::multi_segment,
                  "header: segmented payloads are not supported (offset " +
                      std::to_string(read_u32(datagram, kOffset)) + ")");
  }

  const json sample = json::parse(payload.begin(), payload.end(), nullptr,
                                  /*allow_exceptions=*/false);
  if (sample.is_discarded()) {
    return detail::describe_json_error(payload);
  }
  return extract(sample, read_u16(datagram, kSequence));
}

std::vector<std::uint8_t> encode_opentrackio_datagram(std::span<const std::uint8_t> payload,
                                                      std::uint16_t sequence,
                                                      std::uint8_t encoding) {
  if (payload.size() > kOpenTrackIoMaxPayload) {
    return {};
  }
  std::vector<std::uint8_t> out(kOpenTrackIoHeaderSize);
  std::copy(std::begin(kMagic), std::end(kMagic), out.begin());
  out[kEncoding] = encoding;
  write_u16(out, kSequence, sequence);
  // Bytes 8-11 (segment offset) stay 0: one segment.
  write_u16(out, kLength, static_cast<std::uint16_t>(kLastSegmentFlag | payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  write_u16(out, kChecksum,
            fletcher16(std::span<const std::uint8_t>(out).first(kChecksum), payload));
  return out;
}

std::vector<std::uint8_t> encode_opentrackio(const OpenTrackIoSample &in) {
  json sample = {{"protocol", {{"name", "OpenTrackIO"}, {"version", {1, 0, 0}}}}};
  if (in.sample_id) {
    sample["sampleId"] = *in.sample_id;
  }
  if (in.sample_sequence) {
    sample["timing"]["sequenceNumber"] = *in.sample_sequence;
  }
  if (in.sample_timestamp) {
    sample["timing"]["sampleTimestamp"] = {{"seconds", in.sample_timestamp->seconds},
                                           {"nanoseconds", in.sample_timestamp->nanoseconds}};
  }
  const auto put = [&sample](const json::json_pointer &where, const std::optional<double> &v) {
    if (v) {
      sample[where] = *v;
    }
  };
  put(json::json_pointer("/lens/focusDistance"), in.focus_distance_m);
  put(json::json_pointer("/lens/fStop"), in.f_stop);
  put(json::json_pointer("/lens/pinholeFocalLength"), in.pinhole_focal_length_mm);
  put(json::json_pointer("/lens/encoders/focus"), in.encoder_focus);
  put(json::json_pointer("/lens/encoders/iris"), in.encoder_iris);
  put(json::json_pointer("/lens/encoders/zoom"), in.encoder_zoom);
  for (const OpenTrackIoTransform &t : in.transforms) {
    json entry = {
        {"translation", {{"x", t.pose.x_m}, {"y", t.pose.y_m}, {"z", t.pose.z_m}}},
        {"rotation",
         {{"pan", t.pose.pan_deg}, {"tilt", t.pose.tilt_deg}, {"roll", t.pose.roll_deg}}}};
    if (t.id) {
      entry["id"] = *t.id;
    }
    sample["transforms"].push_back(std::move(entry));
  }

  // `replace` keeps dump() from throwing on a sampleId that is not UTF-8.
  const std::string text = sample.dump(-1, ' ', false, json::error_handler_t::replace);
  const auto *bytes = reinterpret_cast<const std::uint8_t *>(text.data());
  return encode_opentrackio_datagram(std::span(bytes, text.size()), in.header_sequence);
}

const char *to_string(OpenTrackIoError error) {
  switch (error) {
  case OpenTrackIoError::none:
    return "none";
  case OpenTrackIoError::truncated:
    return "truncated";
  case OpenTrackIoError::bad_magic:
    return "bad magic";
  case OpenTrackIoError::length_mismatch:
    return "length mismatch";
  case OpenTrackIoError::bad_checksum:
    return "bad checksum";
  case OpenTrackIoError::unsupported_encoding:
    return "unsupported encoding";
  case OpenTrackIoError::multi_segment:
    return "multi-segment";
  case OpenTrackIoError::malformed_json:
    return "malformed JSON";
  case OpenTrackIoError::wrong_type:
    return "wrong type";
  case OpenTrackIoError::out_of_range:
    return "out of range";
  case OpenTrackIoError::non_finite:
    return "non-finite number";
  }
  return "unknown";
}

} // namespace camhead::hal::lens
