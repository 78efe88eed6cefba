// OpenTrackIO over UDP: the datagram handler and sequence tracking on top of
// the shared UDP loop.
#include "camhead/hal/lens/network/opentrackio_receiver.h"

#include <cmath>

#include "udp_link.h"

namespace camhead::hal::lens {
namespace {

std::optional<std::int32_t> to_counts(const std::optional<double> &normalised) {
  if (!normalised) {
    return std::nullopt;
  }
  // The parser guarantees [0, 1], so the product stays within int32.
  return static_cast<std::int32_t>(std::lround(*normalised * kNormalisedCounts));
}

} // namespace

std::optional<EncoderReading> reading_from_opentrackio(const OpenTrackIoSample &sample,
                                                       std::int64_t t_ns) {
  EncoderReading r;
  r.t_ns = t_ns;
  r.focus = to_counts(sample.encoder_focus);
  r.iris = to_counts(sample.encoder_iris);
  r.zoom = to_counts(sample.encoder_zoom);
  r.focus_distance_m = sample.focus_distance_m;
  r.f_stop = sample.f_stop;
  r.focal_length_mm = sample.pinhole_focal_length_mm;
  r.pose = opentrackio_camera_pose(sample.transforms);
  if (!r.focus && !r.iris && !r.zoom && !r.focus_distance_m && !r.f_stop && !r.focal_length_mm &&
      !r.pose) {
    return std::nullopt;
  }
  return r;
}

OpenTrackIoReceiver::OpenTrackIoReceiver(const OpenTrackIoReceiverConfig &config)
    : link_(std::make_unique<detail::UdpLink>(detail::UdpLinkOptions{
          "opentrackio", config.bind_address, config.port, config.multicast_group,
          config.multicast_interface, config.connected_window})),
      window_ns_(std::chrono::nanoseconds(config.connected_window).count()) {}

OpenTrackIoReceiver::~OpenTrackIoReceiver() = default;

std::string OpenTrackIoReceiver::name() const {
  return link_->name();
}

std::uint16_t OpenTrackIoReceiver::port() const {
  return link_->port();
}

void OpenTrackIoReceiver::track_sequence(std::uint16_t sequence, std::int64_t t_ns) {
  if (expected_sequence_ && t_ns - last_sequence_ns_ <= window_ns_) {
    // Modulo 2^16: 1 .. 0x7FFF ahead is that many datagrams missing; further
    // "ahead" is really behind (late, repeated, or a sender that restarted).
    const auto gap = static_cast<std::uint16_t>(sequence - *expected_sequence_);
    if (gap < 0x8000) {
      link_->count_lost(gap);
    }
  }
  expected_sequence_ = static_cast<std::uint16_t>(sequence + 1);
  last_sequence_ns_ = t_ns;
}

void OpenTrackIoReceiver::poll(std::chrono::milliseconds timeout,
                               std::vector<EncoderReading> &out) {
  link_->poll(timeout, [this, &out](const detail::Datagram &d, std::string &why) {
    OpenTrackIoParseResult parsed = parse_opentrackio(d.bytes);
    if (!parsed) {
      why = std::string("OpenTrackIO: ") + to_string(parsed.error) + ": " + parsed.detail;
      return detail::Verdict::malformed;
    }
    track_sequence(parsed.sample->header_sequence, d.t_ns);
    std::optional<EncoderReading> reading = reading_from_opentrackio(*parsed.sample, d.t_ns);
    if (!reading) {
      return detail::Verdict::ignored;
    }
    out.push_back(*reading);
    return detail::Verdict::reading;
  });
}

EncoderStatus OpenTrackIoReceiver::status() const {
  return link_->status();
}

} // namespace camhead::hal::lens
