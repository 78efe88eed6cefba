// The DRM/KMS sink; see drm_sink.h.
#include "camhead/hal/output/drm/drm_sink.h"

#include <cerrno>
#include <cstring>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/output/sink_base.h"
#include "drm_display.h"

namespace camhead::hal::output {
namespace {

using namespace drm;

constexpr std::int64_t kConnectorCheckNs = 500'000'000;
constexpr std::uint32_t kDisconnected = 2; // DRM_MODE_DISCONNECTED

class DrmSink final : public SinkBase {
public:
  DrmSink(const DrmSinkOptions &options, OpenedDisplay opened)
      : SinkBase(opened.format), options_(options), display_(std::move(opened.display)),
        full_frame_(opened.full_frame),
        name_("drm " + display_->label + " " + display_->connector_name),
        next_check_ns_(base::monotonic_ns() + kConnectorCheckNs) {
    ready("ready, " + opened.summary);
  }

  std::string name() const override { return name_; }

private:
  bool send(std::span<const std::uint8_t> frame, std::int64_t) override {
    const std::int64_t now = base::monotonic_ns();
    if (live_ && now >= next_check_ns_)
      check_connector(now);
    if (!live_ && !resume(now))
      return false; // skipped while it is away; status() says so
    if (display_->flip_pending) {
      std::string error;
      if (!display_->wait_for_flip(error))
        stop_flipping(error);
    }
    copy_into(back(), frame);
    return present();
  }

  bool finish() override {
    std::string error;
    if (display_ != nullptr && !display_->teardown(error))
      return fail("closed, but " + error);
    return closed("closed after " + std::to_string(frames()) +
                  " frames; the picture that was there before is back");
  }

  bool writable() const override { return live_; }

  DumbBuffer &back() { return display_->buffers[static_cast<std::size_t>(1 - display_->front)]; }

  // The frame into the buffer's frame area: one copy where the frame is the
  // mode's size and its rows the buffer's pitch, else row by row.
  void copy_into(DumbBuffer &buffer, std::span<const std::uint8_t> frame) {
    if (full_frame_) {
      std::memcpy(buffer.bytes().data(), frame.data(), frame.size());
      return;
    }
    const std::size_t row = base::row_bytes(format());
    const Placement at = display_->placement;
    for (int y = 0; y < format().height; ++y)
      std::memcpy(buffer.bytes().data() + static_cast<std::size_t>(y + at.y) * buffer.pitch() +
                      static_cast<std::size_t>(at.x) * 4,
                  frame.data() + static_cast<std::size_t>(y) * row, row);
  }

  bool present() {
    Display &d = *display_;
    const int index = 1 - d.front;
    if (d.page_flips) {
      drm_mode_crtc_page_flip flip{};
      flip.crtc_id = d.crtc;
      flip.fb_id = d.buffers[static_cast<std::size_t>(index)].fb_id();
      flip.flags = DRM_MODE_PAGE_FLIP_EVENT;
      flip.user_data = ++d.flip_serial;
      if (d.card.ioctl(DRM_IOCTL_MODE_PAGE_FLIP, flip, true)) {
        d.flip_pending = true;
        d.front = index;
        return true;
      }
      const int err = errno;
      if (err != EINVAL && err != EOPNOTSUPP && err != ENOSYS && err != ENOTTY)
        return lost("DRM_IOCTL_MODE_PAGE_FLIP", err);
      stop_flipping("DRM_IOCTL_MODE_PAGE_FLIP: " + errno_text(err));
    }
    std::string error;
    if (d.show(index, error))
      return true;
    return lost("DRM_IOCTL_MODE_SETCRTC", errno);
  }

  // Page flips do not work here: SETCRTC per frame from now on.
  void stop_flipping(const std::string &why) {
    display_->page_flips = false;
    note_ = "; " + why + ", so each frame is set with SETCRTC (blocking, may tear)";
    say(why + "; presenting each frame with SETCRTC from now on (blocking, may tear)");
  }

  // A presentation failed: the device gone, master taken, the connector
  // unplugged, or one bad request.
  bool lost(const char *what, int err) {
    const std::string reason = std::string(what) + ": " + errno_text(err);
    if (err == ENODEV)
      return card_gone(reason);
    if (err == EACCES || err == EPERM) {
      display_->master = false;
      return go_dark("DRM master was taken (" + reason +
                     ", a VT switch or another program); taking it back every 0.5 s");
    }
    std::string error;
    const std::optional<Connector> now =
        get_connector(display_->card, display_->connector.id, false, error);
    if (now && now->connection == kDisconnected)
      return go_dark("connector unplugged (" + reason + "); waiting for it, every 0.5 s");
    return fail(reason + "; frame dropped");
  }

  // The card itself went away (unplugged, its driver unbound): every ioctl
  // on it fails with ENODEV. It is let go of at once, since a card that
  // comes back while this one is still open is given another number, and
  // looked for every 0.5 s.
  bool card_gone(const std::string &reason) {
    display_.reset();
    live_ = false;
    next_check_ns_ = base::monotonic_ns() + kConnectorCheckNs;
    return fail("the card is gone (" + reason + "); looking for " + options_.card + " every 0.5 s");
  }

  // Whether an ioctl that failed did so because the card is gone.
  static bool gone(const CardFile &card) { return driver_name(card).empty() && errno == ENODEV; }

  bool go_dark(const std::string &why) {
    live_ = false;
    display_->flip_pending = false;
    next_check_ns_ = base::monotonic_ns() + kConnectorCheckNs;
    return fail(why);
  }

  void check_connector(std::int64_t now) {
    next_check_ns_ = now + kConnectorCheckNs;
    std::string error;
    const std::optional<Connector> state =
        get_connector(display_->card, display_->connector.id, false, error);
    if (!state && gone(display_->card)) {
      (void)card_gone(error);
    } else if (!state) {
      (void)go_dark(error);
    } else if (state->connection == kDisconnected) {
      (void)go_dark("connector unplugged; waiting for it, every 0.5 s");
    }
  }

  // Every 0.5 s while dark: the card back (opened again as at open, by the
  // name it was opened by), master back, connector back, mode set again.
  bool resume(std::int64_t now) {
    if (now < next_check_ns_)
      return false;
    next_check_ns_ = now + kConnectorCheckNs;
    if (display_ == nullptr)
      return reopen();
    Display &d = *display_;
    std::string error;
    if (!d.master) {
      int unused = 0;
      if (!d.card.ioctl(DRM_IOCTL_SET_MASTER, unused, true)) {
        const int err = errno;
        if (err == ENODEV) {
          (void)card_gone("DRM_IOCTL_SET_MASTER: " + errno_text(err));
          return false;
        }
        return away("DRM master is still held by another program (" + errno_text(err) + ")");
      }
      d.master = true;
    }
    const std::optional<Connector> state = get_connector(d.card, d.connector.id, false, error);
    if (!state && gone(d.card)) {
      (void)card_gone(error);
      return false;
    }
    if (!state)
      return away(error);
    if (state->connection == kDisconnected)
      return away("connector unplugged; waiting for it, every 0.5 s");
    if (!d.show(d.front, error))
      return away("connector back, but " + error);
    live_ = true;
    ready("back, " + describe_mode(d.mode_summary) + note_);
    return true;
  }

  bool reopen() {
    try {
      OpenedDisplay opened = open_display(options_);
      if (opened.format != format())
        return away("the card is back, but takes " + base::describe(opened.format) +
                    " frames, not " + base::describe(format()) + ": restart to use it");
      display_ = std::move(opened.display);
    } catch (const DrmSinkError &e) {
      return away(std::string("the card is gone; looking for it every 0.5 s: ") + e.what());
    }
    live_ = true;
    ready("the card is back (" + display_->label + "), " + describe_mode(display_->mode_summary) +
          note_);
    return true;
  }

  const DrmSinkOptions options_;
  std::unique_ptr<Display> display_; // null while the card is gone
  const bool full_frame_;
  const std::string name_;
  std::int64_t next_check_ns_;
  bool live_ = true;
  std::string note_; // what changed since open, for later status lines
};

} // namespace

std::unique_ptr<FrameSink> open_drm_sink(const DrmSinkOptions &options) {
  return std::make_unique<DrmSink>(options, open_display(options));
}

} // namespace camhead::hal::output
