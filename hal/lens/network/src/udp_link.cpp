// Sockets, addresses and the receive loop shared by the UDP lens sources. See
// udp_link.h for why they share one loop.
#include "udp_link.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <optional>
#include <stdexcept>
#include <system_error>
#include <utility>

#include <arpa/inet.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "camhead/base/realtime_stamp.h"

namespace camhead::hal::lens::detail {
namespace {

// The largest UDP payload over IPv4 is 65507 bytes; one 64 KiB buffer holds
// any datagram, so MSG_TRUNC can only mean something very odd.
constexpr std::size_t kBufferSize = 65536;

void enable_option(int fd, int level, int option) {
  const int one = 1;
  // Best effort: without kernel stamps the receive time is used, without the
  // overflow counter kernel drops go uncounted. Neither stops reception.
  (void)::setsockopt(fd, level, option, &one, sizeof one);
}

} // namespace

UniqueFd &UniqueFd::operator=(UniqueFd &&other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) {
      ::close(fd_);
    }
    fd_ = other.release();
  }
  return *this;
}

UniqueFd::~UniqueFd() {
  if (fd_ >= 0) {
    ::close(fd_);
  }
}

std::string socket_label(std::string_view protocol, std::string_view address, std::uint16_t port) {
  return std::string(protocol) + " udp " + std::string(address) + ":" + std::to_string(port);
}

std::string to_string(const sockaddr_in &address) {
  char text[INET_ADDRSTRLEN] = {};
  ::inet_ntop(AF_INET, &address.sin_addr, text, sizeof text);
  return std::string(text) + ":" + std::to_string(ntohs(address.sin_port));
}

void throw_errno(const std::string &label, const char *call) {
  throw std::system_error(errno, std::generic_category(), label + ": " + call);
}

in_addr parse_ipv4(const std::string &text, const std::string &label, const char *field) {
  in_addr out{};
  if (::inet_pton(AF_INET, text.c_str(), &out) != 1) {
    throw std::invalid_argument(label + ": " + field + ": \"" + text +
                                "\" is not an IPv4 address (dotted quad, e.g. 0.0.0.0)");
  }
  return out;
}

UniqueFd open_udp_socket(const std::string &label) {
  UniqueFd fd(::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (!fd.valid()) {
    throw_errno(label, "socket");
  }
  return fd;
}

UdpLink::UdpLink(const UdpLinkOptions &options)
    : window_ns_(std::chrono::nanoseconds(options.connected_window).count()) {
  const std::string label = socket_label(options.protocol, options.bind_address, options.port);
  // Every address is checked before a socket exists, so a typo in a board
  // file is reported as such and not as a socket error.
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_port = htons(options.port);
  local.sin_addr = parse_ipv4(options.bind_address, label, "bind address");
  const bool multicast = !options.multicast_group.empty();
  ip_mreq join{};
  if (multicast) {
    join.imr_multiaddr = parse_ipv4(options.multicast_group, label, "multicast group");
    if (!IN_MULTICAST(ntohl(join.imr_multiaddr.s_addr))) {
      throw std::invalid_argument(label + ": multicast group: " + options.multicast_group +
                                  " is not a multicast address (224.0.0.0/4)");
    }
    join.imr_interface.s_addr = htonl(INADDR_ANY);
    if (!options.multicast_interface.empty()) {
      join.imr_interface = parse_ipv4(options.multicast_interface, label, "multicast interface");
    }
  }

  fd_ = open_udp_socket(label);
  if (multicast) {
    // Several programs on one host may listen to the same group and port (a
    // monitor next to the pipeline); for unicast, sharing a port would split
    // the datagrams between them, so there a second bind must fail.
    const int one = 1;
    if (::setsockopt(fd_.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0) {
      throw_errno(label, "SO_REUSEADDR");
    }
  }
  queue_empty_ns_ = monotonic_ns(); // nothing is queued before the bind
  if (::bind(fd_.get(), reinterpret_cast<const sockaddr *>(&local), sizeof local) != 0) {
    throw_errno(label, "bind");
  }
  sockaddr_in bound{};
  socklen_t length = sizeof bound;
  if (::getsockname(fd_.get(), reinterpret_cast<sockaddr *>(&bound), &length) != 0) {
    throw_errno(label, "getsockname");
  }
  port_ = ntohs(bound.sin_port);
  name_ = socket_label(options.protocol, options.bind_address, port_);
  if (multicast) {
    name_ += " group " + options.multicast_group;
    if (::setsockopt(fd_.get(), IPPROTO_IP, IP_ADD_MEMBERSHIP, &join, sizeof join) != 0) {
      throw_errno(name_, "join (IP_ADD_MEMBERSHIP)");
    }
  }
  enable_option(fd_.get(), SOL_SOCKET, SO_TIMESTAMPNS);
  enable_option(fd_.get(), SOL_SOCKET, SO_RXQ_OVFL);
  buffer_.resize(kBufferSize);
  status_.detail = name_ + ": waiting for datagrams";
}

void UdpLink::poll(std::chrono::milliseconds timeout, const DatagramHandler &handle) {
  const std::int64_t deadline =
      monotonic_ns() + std::chrono::nanoseconds(std::max(timeout, {})).count();
  for (;;) {
    const Drained drained = receive_all(handle);
    if (drained.readings > 0 || drained.more) {
      return;
    }
    const std::int64_t left = deadline - monotonic_ns();
    if (left <= 0) {
      return;
    }
    // ppoll rather than poll: its nanosecond timeout neither overshoots the
    // caller's deadline (rounding up) nor spins just before it (rounding down).
    pollfd waiting{fd_.get(), POLLIN, 0};
    const timespec wait{static_cast<time_t>(left / 1'000'000'000),
                        static_cast<long>(left % 1'000'000'000)};
    const int ready = ::ppoll(&waiting, 1, &wait, nullptr);
    if (ready == 0) {
      return;
    }
    if (ready < 0 && errno != EINTR) {
      status_.detail = name_ + ": ppoll: " + std::strerror(errno);
      return;
    }
  }
}

UdpLink::Drained UdpLink::receive_all(const DatagramHandler &handle) {
  Drained drained;
  std::string why;
  // The clocks' offset for this burst's stamps, read after the first.
  std::optional<base::ClockPair> clocks;
  for (int n = 0; n < kMaxBurst; ++n) {
    iovec io{buffer_.data(), buffer_.size()};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t))];
    Datagram d;
    // Should this read find the queue empty, it was empty after this instant.
    const std::int64_t asked_ns = monotonic_ns();
    msghdr message{};
    message.msg_name = &d.from;
    message.msg_namelen = sizeof d.from;
    message.msg_iov = &io;
    message.msg_iovlen = 1;
    message.msg_control = control;
    message.msg_controllen = sizeof control;
    const ssize_t size = ::recvmsg(fd_.get(), &message, MSG_DONTWAIT);
    if (size < 0) {
      if (errno == EINTR) {
        continue;
      }
      if (errno == EAGAIN || errno == EWOULDBLOCK) {
        queue_empty_ns_ = asked_ns;
      } else {
        status_.detail = name_ + ": recvmsg: " + std::strerror(errno);
      }
      return drained;
    }

    // Receipt time: the kernel's stamp, moved to CLOCK_MONOTONIC
    // (realtime_stamp.h); now, for a datagram without one.
    const std::int64_t now = monotonic_ns();
    d.t_ns = now;
    for (cmsghdr *c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
      if (c->cmsg_level != SOL_SOCKET) {
        continue;
      }
      if (c->cmsg_type == SCM_TIMESTAMPNS) {
        timespec stamp{};
        std::memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
        if (!clocks) {
          clocks = base::read_clock_pair();
        }
        d.t_ns = base::receipt_ns(std::int64_t{stamp.tv_sec} * 1'000'000'000 + stamp.tv_nsec,
                                  *clocks, queue_empty_ns_, now);
      } else if (c->cmsg_type == SO_RXQ_OVFL) {
        std::uint32_t counter = 0;
        std::memcpy(&counter, CMSG_DATA(c), sizeof counter);
        kernel_drops_ += static_cast<std::uint32_t>(counter - overflow_counter_); // wraps
        overflow_counter_ = counter;
      }
    }
    // Readings leave in receipt order, so their times never run backwards,
    // even by the few nanoseconds two clocks can disagree by.
    d.t_ns = std::max(d.t_ns, last_valid_ns_);
    d.bytes = std::span<const std::uint8_t>(buffer_.data(), static_cast<std::size_t>(size));

    why.clear();
    const Verdict verdict = (message.msg_flags & MSG_TRUNC) != 0
                                ? (why = "larger than 64 KiB", Verdict::malformed)
                                : handle(d, why);
    if (verdict == Verdict::reading) {
      note_reading(d);
      ++drained.readings;
    } else if (verdict == Verdict::malformed) {
      note_malformed(d, why);
    }
  }
  drained.more = true;
  return drained;
}

void UdpLink::note_reading(const Datagram &d) {
  ++status_.readings;
  const bool silent_too_long = ever_valid_ && !connected_at(d.t_ns);
  if (silent_too_long) {
    ++status_.reconnects;
  }
  if (!ever_valid_ || silent_too_long || d.from.sin_addr.s_addr != last_sender_.sin_addr.s_addr ||
      d.from.sin_port != last_sender_.sin_port) {
    status_.detail = name_ + ": receiving from " + to_string(d.from);
    last_sender_ = d.from;
  }
  ever_valid_ = true;
  last_valid_ns_ = d.t_ns;
}

void UdpLink::note_malformed(const Datagram &d, const std::string &why) {
  ++status_.malformed;
  status_.detail = name_ + ": malformed datagram from " + to_string(d.from) + ": " + why;
}

bool UdpLink::connected_at(std::int64_t t_ns) const {
  return ever_valid_ && t_ns - last_valid_ns_ <= window_ns_;
}

EncoderStatus UdpLink::status() const {
  EncoderStatus s = status_;
  s.connected = connected_at(monotonic_ns());
  return s;
}

} // namespace camhead::hal::lens::detail
