// See drm_display.h.
#include "drm_display.h"

#include <algorithm>
#include <cstring>
#include <optional>

namespace camhead::hal::output::drm {
namespace {

constexpr std::uint8_t kPlaceholderGrey = 128;

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

} // namespace

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

} // namespace camhead::hal::output::drm
