// Output to a display through DRM/KMS: camhead's composite on an HDMI (or
// DisplayPort, panel, virtual) connector, with no compositor or X server.
// The kernel's mode-setting ioctls are used directly (no libdrm), as
// libdrm's modetest and kmscube do through libdrm.
//
// Open: the card (a path, "card0", or a driver name such as "bochs-drm",
// looked up among /dev/dri/card*) is opened and made DRM master
// (DRM_IOCTL_SET_MASTER): only one program may set modes on a card, so a
// running compositor or X server makes open fail, saying so. The connector
// (by its kernel name, "HDMI-A-1", "Virtual-1"; empty: the first connected)
// must be connected. The mode is `mode` ("WxH" or "WxH@Hz", Hz matched to the
// precision written: "@60" takes 59.94 too, "@59.94" does not take 60) or,
// when empty, the connector's preferred one. The frame is shown 1:1, centred
// in the mode with black borders; a frame larger than the mode is refused.
// A CRTC is chosen (the one already driving the connector, else the first
// free one its encoders can use) and its state saved (DRM_IOCTL_MODE_GETCRTC:
// framebuffer, mode, position) for close(). Two XRGB8888 dumb buffers of the
// mode's size are made and mapped; both show black borders around a
// mid-grey (128, 128, 128) frame area, and the first is put on screen at
// once (SETCRTC), so that the display shows the output is live before the
// first composite arrives. Anything that fails throws DrmSinkError
// "CARD (DRIVER): [connector NAME: ]REASON".
//
// Frames: format() is xrgb8888 at the frame size. submit() copies the frame
// into the back dumb buffer, the one copy a display needs: whole when the
// frame is exactly the mode's size (format().stride is then the buffer's
// pitch, which may exceed width * 4), else row by row into the back
// buffer's frame area (the borders are never written again). It then
// presents the back buffer with a page flip that asks for an event
// (DRM_MODE_PAGE_FLIP_EVENT); the next submit() waits for that event before
// it copies, so a buffer is never written while it is being scanned out (on
// a real display that paces the frame loop to the refresh rate). A driver
// that refuses page flips, or whose flip event does not come within 1 s, is
// driven with SETCRTC per frame instead (blocking, may tear); status().detail
// says which. bochs (QEMU's standard VGA) has no vblank: its flips complete
// at once. capture_ns is not used (a display shows frames, it stores no
// stamps).
//
// Loss: the connector's state is read every 0.5 s (the kernel's cached
// state: no probing, which can take tens of milliseconds on HDMI). While it
// is disconnected, or DRM master is taken, submit() sends nothing (the
// frame is skipped) and status() says why; when it is connected again the
// mode is set again and frames resume. A card that went away itself
// (ENODEV: unplugged, its driver unbound) is closed at once and opened
// again every 0.5 s as at open, by the name it was opened by: a driver's
// name finds it under whatever number it comes back as, a path only at that
// path (the hardware lab unplugs and replugs a card 100 times: each back
// within about half a second, bench/RESULTS.md). One that comes back taking
// frames of another layout is refused until a restart.
//
// close(), and the destructor of a sink never closed: the saved CRTC state is
// put back (the framebuffer that was there, so the text console or the
// splash comes back; a CRTC that was off is switched off), the buffers are
// removed and unmapped, DRM master is dropped and the card closed.
//
// Thread safety: as FrameSink (submit and close from one thread; status
// from any).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "camhead/hal/output/frame_sink.h"

namespace camhead::hal::output {

struct DrmSinkOptions {
  // "/dev/dri/card0", "card0", or a DRM driver name ("bochs-drm", "i915",
  // "vc4"): the first /dev/dri/card* whose driver has that name.
  std::string card = "/dev/dri/card0";
  // The connector's kernel name ("HDMI-A-1", "DP-2", "Virtual-1"); empty:
  // the first connected one.
  std::string connector;
  // The frame camhead renders, at most the mode's size.
  int width = 0;
  int height = 0;
  // "WxH" or "WxH@Hz" ("1920x1080@50", "1920x1080@59.94"); empty: the
  // connector's preferred mode.
  std::string mode;
};

// "CARD (DRIVER): REASON", thrown by open_drm_sink only.
class DrmSinkError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

[[nodiscard]] std::unique_ptr<FrameSink> open_drm_sink(const DrmSinkOptions &options);

} // namespace camhead::hal::output
