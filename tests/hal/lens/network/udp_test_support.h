// Helpers of the UDP lens tests: a plain datagram socket that sends raw bytes
// (also broken ones) to a receiver on 127.0.0.1, and a poll loop that collects
// readings with a generous deadline. Real sockets on loopback only: nothing
// leaves the host.
#pragma once

#include <chrono>
#include <cstdint>
#include <ctime>
#include <span>
#include <stdexcept>
#include <vector>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include "camhead/hal/lens/lens_encoder.h"

namespace camhead::hal::lens::test {

class RawSender {
public:
  explicit RawSender(std::uint16_t port) : fd_(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0)) {
    if (fd_ < 0) {
      throw std::runtime_error("test sender: socket failed");
    }
    to_.sin_family = AF_INET;
    to_.sin_port = htons(port);
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~RawSender() { ::close(fd_); }
  RawSender(const RawSender &) = delete;
  RawSender &operator=(const RawSender &) = delete;

  // True when the kernel took the datagram.
  bool send(std::span<const std::uint8_t> bytes) const {
    return ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr *>(&to_),
                    sizeof to_) == static_cast<ssize_t>(bytes.size());
  }

private:
  int fd_;
  sockaddr_in to_{};
};

inline std::int64_t now_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

// Polls until `count` readings arrived or `limit` passed; returns what came.
inline std::vector<EncoderReading>
collect(LensEncoder &source, std::size_t count,
        std::chrono::milliseconds limit = std::chrono::seconds(5)) {
  std::vector<EncoderReading> out;
  const std::int64_t end = now_ns() + std::chrono::nanoseconds(limit).count();
  while (out.size() < count && now_ns() < end) {
    source.poll(std::chrono::milliseconds(100), out);
  }
  return out;
}

} // namespace camhead::hal::lens::test
