// A DRM card as the sink holds it: the descriptor (closed once), ioctls
// retried while a signal interrupts them (as libdrm's drmIoctl), the queries
// of the mode-setting interface in the two-pass form libdrm uses (counts
// first, then arrays; again if a hotplug changed the counts in between), and
// dumb buffers. Errors are values, the reason alone; the sink adds the card's
// and connector's names.
//
// Thread safety: one thread's (the sink's frame thread).
#pragma once

#include <cerrno>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <drm.h>
#include <drm_mode.h>

#include "camhead/hal/device_file.h"

namespace camhead::hal::output::drm {

using hal::errno_text;
// The card's descriptor; its ioctls are asked with retry_again set: DRM
// answers EAGAIN when a mode-setting lock was contended (libdrm's drmIoctl
// retries it too).
using CardFile = hal::DeviceFile;

// Opens a /dev/dri node read-write, non-blocking (events are polled),
// close-on-exec. Refuses what is not a character device.
[[nodiscard]] CardFile open_card(const std::string &path, std::string &error);
// The driver's name (DRM_IOCTL_VERSION): "bochs-drm", "i915", "vc4"; empty
// when the node does not answer.
[[nodiscard]] std::string driver_name(const CardFile &card);
// /dev/dri/card*, in number order.
[[nodiscard]] std::vector<std::string> list_cards();

struct Resources {
  std::vector<std::uint32_t> crtcs;
  std::vector<std::uint32_t> connectors;
  std::vector<std::uint32_t> encoders;
};
[[nodiscard]] std::optional<Resources> get_resources(const CardFile &card, std::string &error);

struct Connector {
  std::uint32_t id = 0;
  std::uint32_t type = 0;
  std::uint32_t type_id = 0;
  std::uint32_t connection = 0; // DRM_MODE_CONNECTED = 1, DISCONNECTED = 2, UNKNOWN = 3
  std::uint32_t encoder_id = 0; // the current one, 0 for none
  std::vector<std::uint32_t> encoders;
  std::vector<drm_mode_modeinfo> modes;
};
// `probe`: ask the driver to probe the connector (EDID over DDC: tens of
// milliseconds on HDMI; the kernel does it only for the DRM master). Without,
// the kernel's cached state and modes.
[[nodiscard]] std::optional<Connector> get_connector(const CardFile &card, std::uint32_t id,
                                                     bool probe, std::string &error);

[[nodiscard]] std::optional<drm_mode_get_encoder> get_encoder(const CardFile &card,
                                                              std::uint32_t id, std::string &error);
[[nodiscard]] std::optional<drm_mode_crtc> get_crtc(const CardFile &card, std::uint32_t id,
                                                    std::string &error);
// DRM_IOCTL_MODE_SETCRTC: `fb` at (x, y) on `connectors` with `mode`; fb 0,
// no connectors and no mode switch the CRTC off.
[[nodiscard]] bool set_crtc(const CardFile &card, std::uint32_t crtc, std::uint32_t fb,
                            std::uint32_t x, std::uint32_t y,
                            std::span<const std::uint32_t> connectors,
                            const drm_mode_modeinfo *mode, std::string &error);

// A dumb buffer (XRGB8888), its framebuffer object and its mapping. Made,
// and unmade, by the sink while it holds the card.
class DumbBuffer {
public:
  DumbBuffer() = default;
  ~DumbBuffer();
  DumbBuffer(DumbBuffer &&other) noexcept;
  DumbBuffer &operator=(DumbBuffer &&other) noexcept;
  DumbBuffer(const DumbBuffer &) = delete;
  DumbBuffer &operator=(const DumbBuffer &) = delete;

  // CREATE_DUMB (32 bpp), ADDFB2 (XRGB8888; ADDFB depth 24 where ADDFB2 is
  // refused), MAP_DUMB and mmap. Empty with `error` naming the step.
  [[nodiscard]] static std::optional<DumbBuffer> create(const CardFile &card, int width, int height,
                                                        std::string &error);
  // Removes the framebuffer, unmaps and destroys the buffer; idempotent. The
  // card must still be open (its descriptor is not kept here).
  void release(const CardFile &card);

  [[nodiscard]] std::uint32_t fb_id() const { return fb_id_; }
  [[nodiscard]] std::uint32_t pitch() const { return pitch_; }
  [[nodiscard]] std::span<std::uint8_t> bytes() const { return {map_, size_}; }

private:
  std::uint32_t handle_ = 0;
  std::uint32_t fb_id_ = 0;
  std::uint32_t pitch_ = 0;
  std::uint8_t *map_ = nullptr;
  std::size_t size_ = 0;
};

} // namespace camhead::hal::output::drm
