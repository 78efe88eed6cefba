// Sends lens state as OpenTrackIO datagrams (opentrackio.h) to a host and
// port, unicast or multicast: camhead as a lens-data source for a downstream
// renderer or recorder, and the live twin of the receiver in tests.
//
// Each send() is one single-segment JSON sample with the fields that are set,
// under a sequence number the sender owns: the 16-bit header sequence and
// timing.sequenceNumber count up together from 0 and advance on every sample
// handed to the socket, including one the socket then refused, so that a
// receiver sees every sample that did not leave as a gap.
//
// Errors: the constructor throws (std::system_error naming the socket and the
// call, std::invalid_argument for an address that is not an IPv4 dotted
// quad); send() never throws and returns 0 or -errno, as the frame loop wants.
//
// Thread safety: none. One thread owns a sender.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "camhead/hal/lens/network/opentrackio.h"

namespace camhead::hal::lens {

struct OpenTrackIoSenderConfig {
  std::string host;                      // IPv4 dotted quad, unicast or 224.0.0.0/4
  std::uint16_t port = kOpenTrackIoPort; // destination port
  // Multicast only: address of the interface the datagrams leave by (empty:
  // the routing table's choice), hop limit (1 = this network only), and
  // whether listeners on this host receive them too.
  std::string multicast_interface;
  int multicast_ttl = 1;
  bool multicast_loop = true;
};

// One lens state and camera pose as OpenTrackIO describes them. Empty fields
// are left out of the sample.
struct OpenTrackIoState {
  std::optional<double> focus_distance_m; // lens.focusDistance, > 0
  std::optional<double> f_stop;           // lens.fStop, > 0
  std::optional<double> focal_length_mm;  // lens.pinholeFocalLength, > 0
  // lens.encoders, normalised [0, 1]; focus 0 is infinity.
  std::optional<double> encoder_focus, encoder_iris, encoder_zoom;
  // The camera's pose relative to the stage, in OpenTrackIO's axes: sent as
  // the one transform "Camera".
  std::optional<TrackedPose> camera;
  // timing.sampleTimestamp on the sender's clock (PTP time on a studio
  // network); left out when empty.
  std::optional<OpenTrackIoTimestamp> timestamp;
};

class OpenTrackIoSender {
public:
  explicit OpenTrackIoSender(const OpenTrackIoSenderConfig &config);
  ~OpenTrackIoSender();
  OpenTrackIoSender(const OpenTrackIoSender &) = delete;
  OpenTrackIoSender &operator=(const OpenTrackIoSender &) = delete;

  // "opentrackio udp -> 127.0.0.1:55555"
  [[nodiscard]] const std::string &name() const { return name_; }

  // Sends one sample. Returns 0, -EINVAL when a field is not finite or out of
  // its range (nothing sent, the sequence does not advance), -EMSGSIZE when
  // the sample does not fit one datagram, or sendto's -errno (-EAGAIN when
  // the socket buffer is full: the sample is dropped, not queued). The reason
  // of the last failure is in last_error().
  [[nodiscard]] int send(const OpenTrackIoState &state);

  // The header sequence number the next sample will carry.
  [[nodiscard]] std::uint16_t next_sequence() const {
    return static_cast<std::uint16_t>(sequence_);
  }
  [[nodiscard]] std::uint64_t sent() const { return sent_; }
  [[nodiscard]] std::uint64_t failed() const { return failed_; }
  [[nodiscard]] const std::string &last_error() const { return last_error_; }

private:
  int fd_ = -1;
  std::string name_;
  std::uint32_t destination_ip_ = 0; // network byte order
  std::uint16_t destination_port_ = 0;
  std::uint64_t sequence_ = 0;
  std::uint64_t sent_ = 0, failed_ = 0;
  std::string last_error_;
};

} // namespace camhead::hal::lens
