// FreeD D1 over UDP: the datagram handler on top of the shared UDP loop.
#include "camhead/hal/lens/network/freed_receiver.h"

#include "camhead/hal/lens/network/freed.h"
#include "udp_link.h"

namespace camhead::hal::lens {

FreedReceiver::FreedReceiver(const FreedReceiverConfig &config)
    : link_(std::make_unique<detail::UdpLink>(detail::UdpLinkOptions{
          "freed", config.bind_address, config.port, {}, {}, config.connected_window})),
      camera_id_(config.camera_id) {}

FreedReceiver::~FreedReceiver() = default;

std::string FreedReceiver::name() const {
  return link_->name();
}

std::uint16_t FreedReceiver::port() const {
  return link_->port();
}

void FreedReceiver::poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) {
  link_->poll(timeout, [this, &out](const detail::Datagram &d, std::string &why) {
    FreedParseResult parsed = parse_freed_d1(d.bytes);
    if (!parsed) {
      why = std::move(parsed.detail);
      return detail::Verdict::malformed;
    }
    const FreedD1 &m = *parsed.message;
    if (camera_id_ && m.camera_id != *camera_id_) {
      ++other_cameras_;
      return detail::Verdict::ignored;
    }
    EncoderReading r;
    r.t_ns = d.t_ns;
    // 24-bit unsigned counts always fit an int32.
    r.focus = static_cast<std::int32_t>(m.focus);
    r.zoom = static_cast<std::int32_t>(m.zoom);
    r.pose = TrackedPose{.x_m = m.x_mm / 1000.0,
                         .y_m = m.y_mm / 1000.0,
                         .z_m = m.z_mm / 1000.0,
                         .pan_deg = m.pan_deg,
                         .tilt_deg = m.tilt_deg,
                         .roll_deg = m.roll_deg};
    out.push_back(r);
    return detail::Verdict::reading;
  });
}

EncoderStatus FreedReceiver::status() const {
  EncoderStatus s = link_->status();
  s.lost = link_->kernel_drops();
  return s;
}

} // namespace camhead::hal::lens
