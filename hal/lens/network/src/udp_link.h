// The socket half shared by the UDP lens receivers and the OpenTrackIO sender:
// an owned file descriptor, IPv4 address parsing with errors that name the
// socket, and the receive loop behind LensEncoder::poll. Private to
// camhead_hal_lens_udp, so no socket type reaches a public header (the
// receivers hold a UdpLink through a forward declaration).
//
// Why one loop for both protocols: the parts that are easy to get subtly
// wrong (waiting no longer than the timeout, stamping each datagram at its
// receipt, bounding the work of one poll, when a source counts as connected)
// are the same for FreeD and OpenTrackIO. Only "what does this datagram mean"
// differs, and that is the handler each receiver passes in.
//
// Thread safety: none. One thread (the lens thread) owns a link.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <netinet/in.h>

#include "camhead/hal/lens/lens_encoder.h"
#include "camhead/hal/lens/monotonic_clock.h"

namespace camhead::hal::lens::detail {

// An owned file descriptor; closes on destruction, moves, never copies.
class UniqueFd {
public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  UniqueFd(UniqueFd &&other) noexcept : fd_(other.release()) {}
  UniqueFd &operator=(UniqueFd &&other) noexcept;
  UniqueFd(const UniqueFd &) = delete;
  UniqueFd &operator=(const UniqueFd &) = delete;
  ~UniqueFd();

  [[nodiscard]] int get() const { return fd_; }
  [[nodiscard]] bool valid() const { return fd_ >= 0; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

private:
  int fd_ = -1;
};

using lens::monotonic_ns;

// "freed udp 0.0.0.0:40000": how messages name a socket.
[[nodiscard]] std::string socket_label(std::string_view protocol, std::string_view address,
                                       std::uint16_t port);
[[nodiscard]] std::string to_string(const sockaddr_in &address);

// Throws std::system_error(errno) whose what() reads "LABEL: CALL: strerror".
[[noreturn]] void throw_errno(const std::string &label, const char *call);

// A dotted-quad IPv4 address (no name lookup), or std::invalid_argument
// "LABEL: FIELD: \"TEXT\" is not an IPv4 address".
[[nodiscard]] in_addr parse_ipv4(const std::string &text, const std::string &label,
                                 const char *field);

// A non-blocking UDP socket, or std::system_error naming the label.
[[nodiscard]] UniqueFd open_udp_socket(const std::string &label);

// One received datagram; `bytes` is valid until the next receive.
struct Datagram {
  std::span<const std::uint8_t> bytes;
  // CLOCK_MONOTONIC at the kernel's receipt (see UdpLink::receive_all).
  std::int64_t t_ns = 0;
  sockaddr_in from{};
};

// What a receiver made of one datagram.
enum class Verdict {
  reading,   // appended a reading; refreshes `connected`
  ignored,   // valid but not for us (another camera, no lens data)
  malformed, // rejected: counted in status.malformed, `why` goes to the detail
};

// handler(datagram, why) -> verdict; fills `why` for malformed datagrams.
using DatagramHandler = std::function<Verdict(const Datagram &, std::string &why)>;

struct UdpLinkOptions {
  std::string protocol; // "freed", "opentrackio": first word of the name
  std::string bind_address = "0.0.0.0";
  std::uint16_t port = 0;
  std::string multicast_group;     // empty: no join
  std::string multicast_interface; // empty: INADDR_ANY, the kernel picks by route
  std::chrono::milliseconds connected_window{1000};
};

// A bound, non-blocking receiving socket with the bookkeeping of
// EncoderStatus. Throws from the constructor only.
class UdpLink {
public:
  explicit UdpLink(const UdpLinkOptions &options);

  // "freed udp 0.0.0.0:40000", with the port the kernel actually bound.
  [[nodiscard]] const std::string &name() const { return name_; }
  [[nodiscard]] std::uint16_t port() const { return port_; }

  // LensEncoder::poll: reads what is queued; when that gave no reading,
  // waits (ppoll) until a datagram arrives or `timeout` has passed, and reads
  // again. Malformed and ignored datagrams do not end the wait. Reads at most
  // kMaxBurst datagrams per call so a flood cannot hold the lens thread;
  // what is left is returned by the next call without waiting.
  void poll(std::chrono::milliseconds timeout, const DatagramHandler &handle);

  // readings, malformed, connected, reconnects, detail; `lost` is what the
  // receiver reported through count_lost().
  [[nodiscard]] EncoderStatus status() const;
  void count_lost(std::uint64_t n) { status_.lost += n; }
  // Datagrams the kernel dropped because the socket's queue was full
  // (SO_RXQ_OVFL), since the link was made.
  [[nodiscard]] std::uint64_t kernel_drops() const { return kernel_drops_; }
  // Whether a reading arrived within the connected window before `t_ns`.
  [[nodiscard]] bool connected_at(std::int64_t t_ns) const;

  static constexpr int kMaxBurst = 1024;

private:
  struct Drained {
    int readings = 0;
    bool more = false; // stopped at kMaxBurst with datagrams still queued
  };
  Drained receive_all(const DatagramHandler &handle);
  void note_reading(const Datagram &d);
  void note_malformed(const Datagram &d, const std::string &why);

  UniqueFd fd_;
  std::string name_;
  std::uint16_t port_ = 0;
  std::int64_t window_ns_ = 0;
  // When the socket's queue was last seen empty (CLOCK_MONOTONIC): every
  // datagram in it now was queued after this. The kernel stamps a datagram
  // as it arrives, a softirq's backlog (microseconds) before it is queued,
  // so a receipt kept no earlier than this is at most that late, never early.
  std::int64_t queue_empty_ns_ = 0;
  std::vector<std::uint8_t> buffer_;

  EncoderStatus status_;
  bool ever_valid_ = false;
  std::int64_t last_valid_ns_ = 0;
  sockaddr_in last_sender_{};
  std::uint32_t overflow_counter_ = 0; // the kernel's cumulative SO_RXQ_OVFL value
  std::uint64_t kernel_drops_ = 0;
};

} // namespace camhead::hal::lens::detail
