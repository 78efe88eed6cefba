// A card set up to show frames, as the DRM sink holds it (drm_sink.h says
// what open does and in which order): the card made DRM master, a
// connector, its mode and CRTC, two dumb buffers, the CRTC's state before
// it for the teardown, and the page-flip cycle. open_display() sets one up
// (at open, and again when a card that went away is back); the sink
// (drm_sink.cpp) drives it frame by frame.
#pragma once

#include <array>
#include <cerrno>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <poll.h>
#include <unistd.h>

#include "camhead/base/monotonic_clock.h"
#include "camhead/base/video_format.h"
#include "camhead/hal/output/drm/drm_sink.h"
#include "drm_card.h"
#include "drm_events.h"
#include "drm_modes.h"

namespace camhead::hal::output::drm {

// A real display flips within one refresh (17 ms at 60 Hz); a second covers
// an emulated one on a loaded machine and still unsticks a driver that never
// sends the event.
inline constexpr int kFlipTimeoutMs = 1000;

// Everything the sink holds on the card, torn down in the order the kernel
// needs: the saved picture back on the CRTC before our framebuffers go (an
// RMFB of the framebuffer on screen would switch the CRTC off), master
// dropped last.
struct Display {
  CardFile card;
  std::string label; // "card0 (bochs-drm)"
  bool master = false;
  Connector connector;
  std::string connector_name;
  std::uint32_t crtc = 0;
  drm_mode_modeinfo mode{};
  ModeSummary mode_summary;
  Placement placement;
  std::array<DumbBuffer, 2> buffers;
  int front = 0;
  bool page_flips = true;
  bool flip_pending = false;
  std::uint64_t flip_serial = 0;

  drm_mode_crtc saved{};
  std::vector<std::uint32_t> saved_connectors;
  bool crtc_changed = false; // our SETCRTC took: close() has a picture to restore

  Display() = default;
  Display(const Display &) = delete;
  Display &operator=(const Display &) = delete;
  ~Display() {
    std::string ignored;
    (void)teardown(ignored);
  }

  [[nodiscard]] bool show(int index, std::string &error) {
    if (!set_crtc(card, crtc, buffers[static_cast<std::size_t>(index)].fb_id(), 0, 0,
                  std::span(&connector.id, 1), &mode, error))
      return false;
    crtc_changed = true;
    front = index;
    return true;
  }

  // Waits for the event of the flip in flight. False when none came within
  // the timeout (or reading failed), with the reason; the flip then counts as
  // done, since a driver that never answers must not stop the output.
  [[nodiscard]] bool wait_for_flip(std::string &error) {
    const std::int64_t deadline = base::monotonic_ns() + std::int64_t{kFlipTimeoutMs} * 1'000'000;
    while (flip_pending) {
      const std::int64_t left_ms = (deadline - base::monotonic_ns()) / 1'000'000;
      if (left_ms <= 0) {
        flip_pending = false;
        error = "no page-flip event within " + std::to_string(kFlipTimeoutMs) + " ms";
        return false;
      }
      pollfd ready{card.fd(), POLLIN, 0};
      const int polled = ::poll(&ready, 1, static_cast<int>(left_ms));
      if (polled < 0 && errno == EINTR)
        continue;
      if (polled < 0) {
        flip_pending = false;
        error = "poll for the page-flip event: " + errno_text(errno);
        return false;
      }
      if (polled == 0)
        continue;
      std::array<std::uint8_t, 1024> bytes{};
      const ssize_t n = ::read(card.fd(), bytes.data(), bytes.size());
      if (n < 0 && (errno == EINTR || errno == EAGAIN))
        continue;
      if (n < 0) {
        flip_pending = false;
        error = "read of the page-flip event: " + errno_text(errno);
        return false;
      }
      for (const DrmEvent &event :
           parse_drm_events(std::span(bytes.data(), static_cast<std::size_t>(n))))
        if (event.type == DRM_EVENT_FLIP_COMPLETE && event.user_data == flip_serial)
          flip_pending = false;
    }
    return true;
  }

  // Puts back what GETCRTC saw at open, then frees everything. True when the
  // saved picture is back (or there was nothing to restore).
  [[nodiscard]] bool teardown(std::string &error) {
    if (!card.is_open())
      return true;
    bool restored = true;
    if (flip_pending) {
      std::string ignored;
      (void)wait_for_flip(ignored);
    }
    if (crtc_changed) {
      if (saved.mode_valid != 0 && saved.fb_id != 0) {
        const std::vector<std::uint32_t> on =
            saved_connectors.empty() ? std::vector<std::uint32_t>{connector.id} : saved_connectors;
        restored = set_crtc(card, crtc, saved.fb_id, saved.x, saved.y, on, &saved.mode, error);
        if (!restored) {
          // Its owner removed it meanwhile: leave the CRTC off rather than
          // showing our last frame frozen.
          error = "could not put back framebuffer " + std::to_string(saved.fb_id) + " (" + error +
                  "); the CRTC was switched off";
          std::string ignored;
          (void)set_crtc(card, crtc, 0, 0, 0, {}, nullptr, ignored);
        }
      } else {
        // The CRTC was off before us: off again.
        restored = set_crtc(card, crtc, 0, 0, 0, {}, nullptr, error);
      }
      crtc_changed = false;
    }
    for (DumbBuffer &buffer : buffers)
      buffer.release(card);
    if (master) {
      int unused = 0;
      (void)card.ioctl(DRM_IOCTL_DROP_MASTER, unused, true);
      master = false;
    }
    card.close();
    return restored;
  }
};

// A display set up as open_drm_sink() describes, and the frames it takes.
struct OpenedDisplay {
  std::unique_ptr<Display> display;
  base::VideoFormat format;
  bool full_frame = false;
  std::string summary;
};

// Sets up `options`'s card as open_drm_sink() describes; throws
// DrmSinkError "CARD (DRIVER): [connector NAME: ]REASON".
[[nodiscard]] OpenedDisplay open_display(const DrmSinkOptions &options);

} // namespace camhead::hal::output::drm
