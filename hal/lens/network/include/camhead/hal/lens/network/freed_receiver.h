// FreeD D1 over UDP as a LensEncoder: a tracking head or lens-encoder box
// sends one 29-byte D1 message per sample (freed.h) to this host.
//
// What a reading carries: focus and zoom as the message's raw 24-bit counts
// (0 .. 0xFFFFFF, lens_control's profile says what they mean); FreeD D1 has no
// iris field, so iris stays empty. The pose is the message's pan, tilt, roll
// and X, Y, Z (millimetres made metres) as FreeD defines them. t_ns is the
// CLOCK_MONOTONIC instant the kernel received the datagram: D1 carries no
// timestamp of its own, and the fixed delay of the sender is the board's
// per-source delay correction.
//
// Status:
//   connected   a valid D1 message from the selected camera arrived within the
//               last `connected_window` (1 s by default: FreeD senders run at
//               the video rate, so a second of silence is an unplugged cable
//               or a stopped sender, not jitter)
//   malformed   datagrams of the wrong length, type byte or checksum
//   lost        datagrams the kernel dropped because its socket queue was full
//               (SO_RXQ_OVFL; reported with the next datagram that arrives).
//               D1 has no sequence number, so loss on the wire is not seen.
//   reconnects  valid messages after more than `connected_window` of silence
//
// Thread safety: none. One thread (the lens thread) constructs, polls and asks
// for status; the class holds no lock because nothing else touches it.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camhead/hal/lens/lens_encoder.h"

namespace camhead::hal::lens {

namespace detail {
class UdpLink;
}

// The port most FreeD senders default to; configurable on all of them.
inline constexpr std::uint16_t kFreedPort = 40000;

struct FreedReceiverConfig {
  std::string bind_address = "0.0.0.0"; // IPv4 dotted quad; 0.0.0.0 = every interface
  std::uint16_t port = kFreedPort;      // 0: an ephemeral port, see FreedReceiver::port()
  // Accept only this camera id (byte 1). Messages of other cameras are valid
  // but not ours: counted in other_cameras(), not in malformed, and they do
  // not keep the source connected.
  std::optional<std::uint8_t> camera_id;
  std::chrono::milliseconds connected_window{1000};
};

class FreedReceiver final : public LensEncoder {
public:
  // Binds the socket. Throws std::system_error when the socket cannot be made
  // or bound ("freed udp 0.0.0.0:40000: bind: Address already in use") and
  // std::invalid_argument for an address that is not an IPv4 dotted quad.
  explicit FreedReceiver(const FreedReceiverConfig &config = {});
  ~FreedReceiver() override;

  // "freed udp 0.0.0.0:40000", with the port actually bound.
  [[nodiscard]] std::string name() const override;
  void poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) override;
  [[nodiscard]] EncoderStatus status() const override;

  // The bound port: the configured one, or the kernel's pick for port 0.
  [[nodiscard]] std::uint16_t port() const;
  // Valid messages dropped by the camera-id filter.
  [[nodiscard]] std::uint64_t other_cameras() const { return other_cameras_; }

private:
  std::unique_ptr<detail::UdpLink> link_;
  std::optional<std::uint8_t> camera_id_;
  std::uint64_t other_cameras_ = 0;
};

} // namespace camhead::hal::lens
