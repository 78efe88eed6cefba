// A camera tracker for the live-pipeline tests: sends a fixed pose over UDP
// to this host as a FreeD head or an OpenTrackIO tracker does, whether or
// not anyone listens.
#pragma once

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <thread>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include "camhead/hal/lens/network/freed.h"
#include "camhead/hal/lens/network/opentrackio_sender.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {

// A port of `type` (SOCK_DGRAM, SOCK_STREAM) nobody on this host listens on now.
inline std::uint16_t free_port(int type) {
  const int fd = ::socket(AF_INET, type, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  EXPECT_EQ(::bind(fd, reinterpret_cast<const sockaddr *>(&address), sizeof address), 0);
  EXPECT_EQ(::getsockname(fd, reinterpret_cast<sockaddr *>(&address), &size), 0);
  ::close(fd);
  return ntohs(address.sin_port);
}
inline std::uint16_t free_udp_port() {
  return free_port(SOCK_DGRAM);
}

// Sends a pose 1 m up, panned by `pan_deg`, at 200 Hz while it lives; with
// a `swing_s`, panning to and fro, pan_deg sin(2 pi t / swing_s).
class Tracker {
public:
  Tracker(const std::string &type, std::uint16_t port, double pan_deg, double swing_s = 0.0)
      : thread_([this, type, port, pan_deg, swing_s] {
          const auto start = std::chrono::steady_clock::now();
          hal::lens::OpenTrackIoSenderConfig config;
          config.host = "127.0.0.1";
          config.port = port;
          hal::lens::OpenTrackIoSender otio(config);
          const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
          sockaddr_in to{};
          to.sin_family = AF_INET;
          to.sin_port = htons(port);
          to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
          while (!stop_) {
            const double t =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const double pan =
                swing_s > 0.0 ? pan_deg * std::sin(2.0 * std::numbers::pi * t / swing_s) : pan_deg;
            if (type == "freed") {
              hal::lens::FreedD1 m;
              m.pan_deg = pan;
              m.x_mm = 0.0;
              m.y_mm = 0.0;
              m.z_mm = 1000.0; // the scene's camera height: 1 m up
              const auto bytes = hal::lens::encode_freed_d1(m);
              (void)::sendto(fd, bytes.data(), bytes.size(), 0,
                             reinterpret_cast<const sockaddr *>(&to), sizeof to);
            } else {
              hal::lens::OpenTrackIoState state;
              state.camera = hal::lens::TrackedPose{.z_m = 1.0, .pan_deg = pan};
              (void)otio.send(state);
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
          }
          ::close(fd);
        }) {}
  ~Tracker() {
    stop_ = true;
    thread_.join();
  }

private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

} // namespace camhead::pipeline
