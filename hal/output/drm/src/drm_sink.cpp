// The DRM/KMS sink; see drm_sink.h.
#include "camhead/hal/output/drm/drm_sink.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <mutex>
#include <optional>
#include <vector>

#include <poll.h>
#include <unistd.h>

#include "camhead/base/monotonic_clock.h"
#include "drm_card.h"
#include "drm_events.h"
#include "drm_modes.h"

namespace camhead::hal::output {
namespace {

using namespace drm;

constexpr std::uint8_t kPlaceholderGrey = 128;
// A real display flips within one refresh (17 ms at 60 Hz); a second covers
// an emulated one on a loaded machine and still unsticks a driver that never
// sends the event.
constexpr int kFlipTimeoutMs = 1000;
constexpr std::int64_t kConnectorCheckNs = 500'000'000;
constexpr std::uint32_t kDisconnected = 2; // DRM_MODE_DISCONNECTED

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

[[noreturn]] void fail_open(const std::string &who, const std::string &reason) {
  throw DrmSinkError(who + ": " + reason);
}

std::string basename_of(const std::string &path) {
  const std::size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// Opens the card the options name and labels it "card0 (bochs-drm)".
void open_named_card(const std::string &spec, Display &display) {
  const CardSpec card = classify_card(spec);
  std::string error;
  if (card.kind == CardSpec::Kind::path) {
    display.card = open_card(card.value, error);
    if (!display.card.is_open())
      fail_open(card.value, error);
    display.label = basename_of(card.value) + " (" + driver_name(display.card) + ")";
    return;
  }
  std::string found;
  for (const std::string &path : list_cards()) {
    std::string ignored;
    CardFile candidate = open_card(path, ignored);
    const std::string driver = candidate.is_open() ? driver_name(candidate) : "cannot open";
    if (candidate.is_open() && driver == card.value) {
      display.card = std::move(candidate);
      display.label = basename_of(path) + " (" + driver + ")";
      return;
    }
    found += (found.empty() ? "" : ", ") + basename_of(path) + " (" + driver + ")";
  }
  fail_open("drm", "no card with driver '" + card.value + "' (" +
                       (found.empty() ? "/dev/dri has no card*" : "/dev/dri has " + found) +
                       "): is its module loaded?");
}

void become_master(Display &display) {
  int unused = 0;
  if (display.card.ioctl(DRM_IOCTL_SET_MASTER, unused, true)) {
    display.master = true;
    return;
  }
  const int err = errno;
  // EBUSY as Linux 6.1 says it; older kernels said EINVAL.
  if (err == EBUSY || err == EINVAL)
    fail_open(display.label,
              "another program is DRM master of this card (a compositor, an X server or another "
              "camhead) and sets its modes: stop it, or choose another card "
              "(DRM_IOCTL_SET_MASTER: " +
                  errno_text(err) + ")");
  if (err == EACCES || err == EPERM)
    fail_open(display.label, "not allowed to become DRM master (DRM_IOCTL_SET_MASTER: " +
                                 errno_text(err) + "): run as root, or from the active session");
  fail_open(display.label, "DRM_IOCTL_SET_MASTER: " + errno_text(err));
}

std::string connector_list(const std::vector<Connector> &connectors) {
  std::string text;
  for (const Connector &c : connectors)
    text += (text.empty() ? "" : ", ") + connector_name(c.type, c.type_id) + " (" +
            std::string(connection_name(c.connection)) + ")";
  return text.empty() ? "no connectors" : text;
}

void choose_connector(const DrmSinkOptions &options, const Resources &resources, Display &display,
                      std::vector<Connector> &all) {
  std::string error;
  for (const std::uint32_t id : resources.connectors) {
    // Master already: this probes, so the modes are current.
    std::optional<Connector> connector = get_connector(display.card, id, true, error);
    if (!connector)
      fail_open(display.label, error);
    all.push_back(std::move(*connector));
  }
  const Connector *chosen = nullptr;
  for (const Connector &connector : all) {
    const std::string name = connector_name(connector.type, connector.type_id);
    if (options.connector.empty() ? connector.connection == 1 : name == options.connector) {
      chosen = &connector;
      break;
    }
  }
  if (chosen == nullptr && options.connector.empty())
    fail_open(display.label, "no connected connector: " + connector_list(all));
  if (chosen == nullptr)
    fail_open(display.label,
              "no connector " + options.connector + "; the card has " + connector_list(all));
  display.connector = *chosen;
  display.connector_name = connector_name(chosen->type, chosen->type_id);
  if (chosen->connection != 1)
    fail_open(display.label, "connector " + display.connector_name + ": " +
                                 std::string(connection_name(chosen->connection)) +
                                 " (nothing plugged in, or the display is off)");
}

void choose_crtc_for(const Resources &resources, const std::vector<Connector> &all,
                     Display &display) {
  std::string error;
  const auto encoder_of = [&](std::uint32_t id) {
    std::optional<drm_mode_get_encoder> encoder = get_encoder(display.card, id, error);
    if (!encoder)
      fail_open(display.label, "connector " + display.connector_name + ": " + error);
    return EncoderSummary{encoder->encoder_id, encoder->crtc_id, encoder->possible_crtcs};
  };
  std::vector<EncoderSummary> encoders;
  for (const std::uint32_t id : display.connector.encoders)
    encoders.push_back(encoder_of(id));
  // CRTCs that show another connector now, and the connectors that share
  // whichever CRTC we take (so close() lights them all again).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> feeding; // (connector, crtc)
  for (const Connector &other : all)
    if (other.encoder_id != 0)
      feeding.emplace_back(other.id, encoder_of(other.encoder_id).crtc_id);
  std::vector<std::uint32_t> busy;
  for (const auto &[connector, crtc] : feeding)
    if (connector != display.connector.id && crtc != 0)
      busy.push_back(crtc);
  const std::optional<std::uint32_t> crtc =
      choose_crtc(display.connector.encoder_id, encoders, resources.crtcs, busy);
  if (!crtc)
    fail_open(display.label, "connector " + display.connector_name +
                                 ": no free CRTC (each one its encoders can use shows another "
                                 "connector)");
  display.crtc = *crtc;
  for (const auto &[connector, fed] : feeding)
    if (fed == *crtc)
      display.saved_connectors.push_back(connector);
  std::optional<drm_mode_crtc> saved = get_crtc(display.card, *crtc, error);
  if (!saved)
    fail_open(display.label, "connector " + display.connector_name + ": " + error);
  display.saved = *saved;
}

// Black everywhere, mid-grey where the frame will be.
void paint_placeholder(const DumbBuffer &buffer, int mode_height, Placement at, int width,
                       int height) {
  const std::span<std::uint8_t> bytes = buffer.bytes();
  std::fill(bytes.begin(), bytes.end(), std::uint8_t{0});
  for (int row = 0; row < height && row + at.y < mode_height; ++row) {
    std::uint8_t *line = bytes.data() + static_cast<std::size_t>(row + at.y) * buffer.pitch() +
                         static_cast<std::size_t>(at.x) * 4;
    std::memset(line, kPlaceholderGrey, static_cast<std::size_t>(width) * 4);
  }
}

// A display set up as open_drm_sink() describes, and the frames it takes.
struct OpenedDisplay {
  std::unique_ptr<Display> display;
  base::VideoFormat format;
  bool full_frame = false;
  std::string summary;
};

OpenedDisplay open_display(const DrmSinkOptions &options);

class DrmSink final : public FrameSink {
public:
  DrmSink(const DrmSinkOptions &options, OpenedDisplay opened)
      : options_(options), display_(std::move(opened.display)), format_(opened.format),
        full_frame_(opened.full_frame),
        name_("drm " + display_->label + " " + display_->connector_name),
        next_check_ns_(base::monotonic_ns() + kConnectorCheckNs) {
    status_.connected = true;
    status_.detail = name() + ": ready, " + opened.summary;
  }

  std::string name() const override { return name_; }
  base::VideoFormat format() const override { return format_; }

  bool submit(std::span<const std::uint8_t> frame, std::int64_t) override {
    if (closed_)
      return fail("submit after close");
    if (std::string wrong = wrong_frame_size(frame, format_); !wrong.empty())
      return fail(wrong);
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
    if (!present())
      return false;
    const std::lock_guard lock(mutex_);
    ++status_.frames;
    return true;
  }

  bool close() override {
    if (closed_)
      return fail("closed twice");
    closed_ = true;
    std::string error;
    const bool restored = display_ == nullptr || display_->teardown(error);
    const std::lock_guard lock(mutex_);
    status_.connected = false;
    if (!restored) {
      ++status_.errors;
      status_.detail = name() + ": closed, but " + error;
      return false;
    }
    status_.detail = name() + ": closed after " + std::to_string(status_.frames) +
                     " frames; the picture that was there before is back";
    return true;
  }

  SinkStatus status() const override {
    const std::lock_guard lock(mutex_);
    return status_;
  }

private:
  DumbBuffer &back() { return display_->buffers[static_cast<std::size_t>(1 - display_->front)]; }

  // The frame into the buffer's frame area: one copy where the frame is the
  // mode's size and its rows the buffer's pitch, else row by row.
  void copy_into(DumbBuffer &buffer, std::span<const std::uint8_t> frame) {
    if (full_frame_) {
      std::memcpy(buffer.bytes().data(), frame.data(), frame.size());
      return;
    }
    const std::size_t row = base::row_bytes(format_);
    const Placement at = display_->placement;
    for (int y = 0; y < format_.height; ++y)
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
    const std::lock_guard lock(mutex_);
    note_ = "; " + why + ", so each frame is set with SETCRTC (blocking, may tear)";
    status_.detail = name() + ": " + why +
                     "; presenting each frame with SETCRTC from now on "
                     "(blocking, may tear)";
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
        return still_dark("DRM master is still held by another program (" + errno_text(err) + ")");
      }
      d.master = true;
    }
    const std::optional<Connector> state = get_connector(d.card, d.connector.id, false, error);
    if (!state && gone(d.card)) {
      (void)card_gone(error);
      return false;
    }
    if (!state)
      return still_dark(error);
    if (state->connection == kDisconnected)
      return still_dark("connector unplugged; waiting for it, every 0.5 s");
    if (!d.show(d.front, error))
      return still_dark("connector back, but " + error);
    live_ = true;
    const std::lock_guard lock(mutex_);
    status_.connected = true;
    status_.detail = name() + ": back, " + describe_mode(d.mode_summary) + note_;
    return true;
  }

  bool reopen() {
    try {
      OpenedDisplay opened = open_display(options_);
      if (opened.format != format_)
        return still_dark("the card is back, but takes " + base::describe(opened.format) +
                          " frames, not " + base::describe(format_) + ": restart to use it");
      display_ = std::move(opened.display);
    } catch (const DrmSinkError &e) {
      return still_dark(std::string("the card is gone; looking for it every 0.5 s: ") + e.what());
    }
    live_ = true;
    const std::lock_guard lock(mutex_);
    status_.connected = true;
    status_.detail = name() + ": the card is back (" + display_->label + "), " +
                     describe_mode(display_->mode_summary) + note_;
    return true;
  }

  bool still_dark(const std::string &why) {
    const std::lock_guard lock(mutex_);
    status_.connected = false;
    status_.detail = name() + ": " + why;
    return false;
  }

  bool fail(const std::string &reason) {
    const std::lock_guard lock(mutex_);
    ++status_.errors;
    status_.detail = name() + ": " + reason;
    status_.connected = live_ && !closed_;
    return false;
  }

  const DrmSinkOptions options_;
  std::unique_ptr<Display> display_; // null while the card is gone
  const base::VideoFormat format_;
  const bool full_frame_;
  const std::string name_;
  std::int64_t next_check_ns_;
  bool live_ = true;
  bool closed_ = false;
  std::string note_; // what changed since open, for later status lines

  mutable std::mutex mutex_; // guards status_
  SinkStatus status_;
};

OpenedDisplay open_display(const DrmSinkOptions &options) {
  if (options.card.empty())
    fail_open("drm", "no card named (a path, \"card0\" or a driver name)");
  base::VideoFormat format;
  format.pixel = base::PixelFormat::xrgb8888;
  format.width = options.width;
  format.height = options.height;
  format.range = base::ColorRange::full;
  if (const std::string reason = base::check_video_format(format); !reason.empty())
    fail_open(options.card, "frame: " + reason);
  std::string error;
  std::optional<ModeRequest> request;
  if (!options.mode.empty()) {
    request = parse_mode_spec(options.mode, error);
    if (!request)
      fail_open(options.card, error);
  }

  auto display = std::make_unique<Display>();
  open_named_card(options.card, *display);
  Display &d = *display;
  become_master(d);
  drm_get_cap dumb{};
  dumb.capability = DRM_CAP_DUMB_BUFFER;
  if (!d.card.ioctl(DRM_IOCTL_GET_CAP, dumb, true) || dumb.value == 0)
    fail_open(d.label, "the driver offers no dumb buffers (DRM_CAP_DUMB_BUFFER)");
  const std::optional<Resources> resources = get_resources(d.card, error);
  if (!resources)
    fail_open(d.label, error);

  std::vector<Connector> all;
  choose_connector(options, *resources, d, all);
  const std::string where = "connector " + d.connector_name;
  std::vector<ModeSummary> modes;
  for (const drm_mode_modeinfo &mode : d.connector.modes)
    modes.push_back(summarise(mode));
  const std::optional<std::size_t> chosen = choose_mode(modes, request, error);
  if (!chosen)
    fail_open(d.label, where + ": " + error);
  d.mode = d.connector.modes[*chosen];
  d.mode_summary = modes[*chosen];
  const std::optional<Placement> placement =
      centre_frame(options.width, options.height, d.mode.hdisplay, d.mode.vdisplay, error);
  if (!placement)
    fail_open(d.label, where + ", mode " + describe_mode(d.mode_summary) + ": " + error);
  d.placement = *placement;
  choose_crtc_for(*resources, all, d);

  for (DumbBuffer &buffer : d.buffers) {
    std::optional<DumbBuffer> made =
        DumbBuffer::create(d.card, d.mode.hdisplay, d.mode.vdisplay, error);
    if (!made)
      fail_open(d.label, where + ": " + error);
    buffer = std::move(*made);
    paint_placeholder(buffer, d.mode.vdisplay, d.placement, options.width, options.height);
  }
  if (!d.show(0, error))
    fail_open(d.label, where + ", mode " + describe_mode(d.mode_summary) + ": " + error);

  // A frame the mode's size comes at the buffers' pitch: one copy, whole.
  const bool full_frame = options.width == d.mode.hdisplay && options.height == d.mode.vdisplay;
  if (full_frame)
    format.stride = static_cast<int>(d.buffers[0].pitch());
  std::string summary = base::describe(format) + " in " + describe_mode(d.mode_summary) +
                        " on CRTC " + std::to_string(d.crtc);
  if (full_frame)
    summary += ", full screen (each frame copied whole into the back buffer, stride " +
               std::to_string(format.stride) + ")";
  else
    summary += ", centred at (" + std::to_string(d.placement.x) + ", " +
               std::to_string(d.placement.y) +
               ") with black borders, copied into the back buffer each frame";
  summary += ", page flips; mid-grey until the first frame";
  return {std::move(display), format, full_frame, summary};
}

} // namespace

std::unique_ptr<FrameSink> open_drm_sink(const DrmSinkOptions &options) {
  return std::make_unique<DrmSink>(options, open_display(options));
}

} // namespace camhead::hal::output
