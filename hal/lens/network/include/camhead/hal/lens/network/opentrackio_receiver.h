// OpenTrackIO over UDP as a LensEncoder: a tracking system or lens controller
// sends one JSON sample per datagram (opentrackio.h), unicast or to a
// multicast group.
//
// What a reading carries:
//   focus, iris, zoom    lens.encoders, normalised [0, 1] on the wire, scaled to
//                        counts 0 .. kNormalisedCounts (rounded). Focus keeps
//                        OpenTrackIO's direction: 0 is infinity. A profile for
//                        such a source is written in these counts.
//   focus_distance_m     lens.focusDistance, as sent
//   f_stop               lens.fStop, as sent
//   focal_length_mm      lens.pinholeFocalLength, as sent
//   pose                 the camera's pose: the sample's transforms composed
//                        (opentrackio_camera_pose), OpenTrackIO's axes
//   t_ns                 the CLOCK_MONOTONIC instant the kernel received the
//                        datagram. timing.sampleTimestamp is the sender's (PTP)
//                        clock, which this host cannot map without knowing
//                        the offset; the sender's fixed latency is
//                        lens_control's per-source delay correction.
// A sample without any of these fields is valid but gives no reading.
//
// Status:
//   connected   a reading arrived within the last `connected_window` (1 s by
//               default: senders run at the video rate, a second of silence is
//               a stopped sender or a broken link, not jitter)
//   malformed   datagrams the parser rejects (header, checksum, JSON, a field
//               of the wrong type or range); the detail names the field
//   lost        gaps in the 16-bit header sequence number. Counted only
//               between datagrams less than `connected_window` apart; a
//               backwards step (reordered, repeated or a restarted sender)
//               resynchronises without counting. Loss in the kernel queue
//               shows up here too, as a gap.
//   reconnects  readings after more than `connected_window` of silence
//
// Thread safety: none. One thread (the lens thread) constructs, polls and asks
// for status.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camhead/hal/lens/lens_encoder.h"
#include "camhead/hal/lens/network/opentrackio.h"

namespace camhead::hal::lens {

namespace detail {
class UdpLink;
}

struct OpenTrackIoReceiverConfig {
  std::string bind_address = "0.0.0.0";  // IPv4 dotted quad; 0.0.0.0 = every interface
  std::uint16_t port = kOpenTrackIoPort; // 0: an ephemeral port, see port()
  // IPv4 multicast group to join (224.0.0.0/4); empty: unicast only. With a
  // group, the port may be shared with other listeners on this host.
  std::string multicast_group;
  // Address of the interface to join the group on; empty: the kernel's pick.
  std::string multicast_interface;
  std::chrono::milliseconds connected_window{1000};
};

// The reading for one parsed sample (see the table above), at `t_ns`; empty
// when the sample carries no lens field. Pure, for tests and tools.
[[nodiscard]] std::optional<EncoderReading> reading_from_opentrackio(const OpenTrackIoSample &lens,
                                                                     std::int64_t t_ns);

class OpenTrackIoReceiver final : public LensEncoder {
public:
  // Binds (and joins). Throws std::system_error naming the socket and the
  // call that failed ("opentrackio udp 0.0.0.0:55555: bind: Address already in
  // use") and std::invalid_argument for an address that is not IPv4 or a
  // group outside 224.0.0.0/4.
  explicit OpenTrackIoReceiver(const OpenTrackIoReceiverConfig &config = {});
  ~OpenTrackIoReceiver() override;

  // "opentrackio udp 0.0.0.0:55555[ group G]", with the port actually bound.
  [[nodiscard]] std::string name() const override;
  void poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) override;
  [[nodiscard]] EncoderStatus status() const override;

  [[nodiscard]] std::uint16_t port() const;

private:
  void track_sequence(std::uint16_t sequence, std::int64_t t_ns);

  std::unique_ptr<detail::UdpLink> link_;
  std::int64_t window_ns_ = 0;
  std::optional<std::uint16_t> expected_sequence_;
  std::int64_t last_sequence_ns_ = 0;
};

} // namespace camhead::hal::lens
