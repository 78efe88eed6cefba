// OpenTrackIO sender: validation, sequence numbering and the socket; the
// sample itself is built by encode_opentrackio (opentrackio.cpp).
#include "camhead/hal/lens/network/opentrackio_sender.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <vector>

#include <arpa/inet.h>
#include <sys/socket.h>
#include <unistd.h>

#include "udp_link.h"

namespace camhead::hal::lens {
namespace {

// The field name of the first value that OpenTrackIO cannot carry, or null.
const char *invalid_field(const OpenTrackIoState &s) {
  const auto positive = [](const std::optional<double> &v) {
    return !v || (std::isfinite(*v) && *v > 0.0);
  };
  const auto unit = [](const std::optional<double> &v) { return !v || (*v >= 0.0 && *v <= 1.0); };
  if (!positive(s.focus_distance_m)) {
    return "lens.focusDistance must be finite and > 0";
  }
  if (!positive(s.f_stop)) {
    return "lens.fStop must be finite and > 0";
  }
  if (!positive(s.focal_length_mm)) {
    return "lens.pinholeFocalLength must be finite and > 0";
  }
  if (!unit(s.encoder_focus)) {
    return "lens.encoders.focus must be within [0, 1]";
  }
  if (!unit(s.encoder_iris)) {
    return "lens.encoders.iris must be within [0, 1]";
  }
  if (!unit(s.encoder_zoom)) {
    return "lens.encoders.zoom must be within [0, 1]";
  }
  if (s.camera) {
    const TrackedPose &c = *s.camera;
    for (const double v : {c.x_m, c.y_m, c.z_m, c.pan_deg, c.tilt_deg, c.roll_deg}) {
      if (!std::isfinite(v)) {
        return "transforms[0]: translation and rotation must be finite";
      }
    }
  }
  if (s.timestamp && s.timestamp->nanoseconds >= 1'000'000'000) {
    return "timing.sampleTimestamp.nanoseconds must be < 1e9";
  }
  return nullptr;
}

void set_option(int fd, int level, int option, int value, const std::string &label,
                const char *call) {
  if (::setsockopt(fd, level, option, &value, sizeof value) != 0) {
    detail::throw_errno(label, call);
  }
}

} // namespace

OpenTrackIoSender::OpenTrackIoSender(const OpenTrackIoSenderConfig &config)
    : name_("opentrackio udp -> " + config.host + ":" + std::to_string(config.port)),
      destination_port_(config.port) {
  const in_addr host = detail::parse_ipv4(config.host, name_, "host");
  destination_ip_ = host.s_addr;
  in_addr interface {};
  interface.s_addr = htonl(INADDR_ANY);
  if (!config.multicast_interface.empty()) {
    interface = detail::parse_ipv4(config.multicast_interface, name_, "multicast interface");
  }
  detail::UniqueFd fd = detail::open_udp_socket(name_);
  if (IN_MULTICAST(ntohl(host.s_addr))) {
    set_option(fd.get(), IPPROTO_IP, IP_MULTICAST_TTL, config.multicast_ttl, name_,
               "IP_MULTICAST_TTL");
    set_option(fd.get(), IPPROTO_IP, IP_MULTICAST_LOOP, config.multicast_loop ? 1 : 0, name_,
               "IP_MULTICAST_LOOP");
    if (!config.multicast_interface.empty() &&
        ::setsockopt(fd.get(), IPPROTO_IP, IP_MULTICAST_IF, &interface, sizeof interface) != 0) {
      detail::throw_errno(name_, "IP_MULTICAST_IF");
    }
  }
  fd_ = fd.release();
}

OpenTrackIoSender::~OpenTrackIoSender() {
  if (fd_ >= 0) {
    ::close(fd_);
  }
}

int OpenTrackIoSender::send(const OpenTrackIoState &state) {
  if (const char *why = invalid_field(state)) {
    ++failed_;
    last_error_ = name_ + ": " + why;
    return -EINVAL;
  }
  OpenTrackIoSample sample;
  sample.header_sequence = static_cast<std::uint16_t>(sequence_);
  sample.sample_sequence = sequence_;
  sample.sample_timestamp = state.timestamp;
  sample.focus_distance_m = state.focus_distance_m;
  sample.f_stop = state.f_stop;
  sample.pinhole_focal_length_mm = state.focal_length_mm;
  sample.encoder_focus = state.encoder_focus;
  sample.encoder_iris = state.encoder_iris;
  sample.encoder_zoom = state.encoder_zoom;
  if (state.camera) {
    sample.transforms.push_back({.pose = *state.camera, .id = "Camera"});
  }
  const std::vector<std::uint8_t> datagram = encode_opentrackio(sample);
  if (datagram.empty()) {
    ++failed_;
    last_error_ = name_ + ": sample does not fit one datagram";
    return -EMSGSIZE;
  }
  ++sequence_;

  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(destination_port_);
  to.sin_addr.s_addr = destination_ip_;
  const ssize_t sent = ::sendto(fd_, datagram.data(), datagram.size(), MSG_DONTWAIT | MSG_NOSIGNAL,
                                reinterpret_cast<const sockaddr *>(&to), sizeof to);
  if (sent < 0) {
    const int error = errno;
    ++failed_;
    last_error_ = name_ + ": sendto: " + std::strerror(error);
    return -error;
  }
  ++sent_;
  return 0;
}

} // namespace camhead::hal::lens
