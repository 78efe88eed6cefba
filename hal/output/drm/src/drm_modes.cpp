// See drm_modes.h.
#include "drm_modes.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace camhead::hal::output::drm {
namespace {

// A positive decimal integer that fills `text` exactly.
std::optional<int> parse_positive(std::string_view text) {
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || value <= 0)
    return std::nullopt;
  return value;
}

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

std::string offered(std::span<const ModeSummary> modes) {
  if (modes.empty())
    return "none";
  std::string text;
  for (const ModeSummary &mode : modes) {
    if (!text.empty())
      text += ", ";
    text += describe_mode(mode);
    if (mode.preferred)
      text += " (preferred)";
  }
  return text;
}

} // namespace

CardSpec classify_card(std::string_view card) {
  if (card.find('/') != std::string_view::npos)
    return {CardSpec::Kind::path, std::string(card)};
  if (card.starts_with("card") && card.size() > 4 &&
      std::all_of(card.begin() + 4, card.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return {CardSpec::Kind::path, "/dev/dri/" + std::string(card)};
  return {CardSpec::Kind::driver, std::string(card)};
}

std::string connector_name(std::uint32_t type, std::uint32_t type_id) {
  // drm_connector_enum_list in the kernel's drm_connector.c, by type number.
  static constexpr std::array<std::string_view, 21> names = {
      "Unknown", "VGA",       "DVI-I", "DVI-D", "DVI-A",     "Composite", "SVIDEO",
      "LVDS",    "Component", "DIN",   "DP",    "HDMI-A",    "HDMI-B",    "TV",
      "eDP",     "Virtual",   "DSI",   "DPI",   "Writeback", "SPI",       "USB"};
  const std::string type_name =
      type < names.size() ? std::string(names[type]) : "type" + std::to_string(type);
  return type_name + "-" + std::to_string(type_id);
}

std::string_view connection_name(std::uint32_t connection) {
  switch (connection) {
  case 1:
    return "connected";
  case 2:
    return "disconnected";
  default:
    return "unknown";
  }
}

std::optional<ModeRequest> parse_mode_spec(std::string_view spec, std::string &error) {
  const auto bad = [&](const char *why) -> std::optional<ModeRequest> {
    error = "mode '" + std::string(spec) + "': " + why;
    return std::nullopt;
  };
  ModeRequest request;
  const std::size_t at = spec.find('@');
  const std::string_view size = spec.substr(0, at);
  const std::size_t x = size.find('x');
  if (x == std::string_view::npos)
    return bad("not WxH or WxH@Hz (\"1920x1080\", \"1920x1080@50\")");
  const std::optional<int> width = parse_positive(size.substr(0, x));
  const std::optional<int> height = parse_positive(size.substr(x + 1));
  if (!width || !height)
    return bad("the width and height must be positive whole numbers (\"1920x1080\")");
  request.width = *width;
  request.height = *height;
  if (at == std::string_view::npos)
    return request;

  const std::string_view rate = spec.substr(at + 1);
  const std::size_t dot = rate.find('.');
  const std::string_view whole = rate.substr(0, dot);
  const std::string_view fraction =
      dot == std::string_view::npos ? std::string_view{} : rate.substr(dot + 1);
  const auto digits = [](std::string_view text) {
    return !text.empty() &&
           std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (!digits(whole) || (dot != std::string_view::npos && !digits(fraction)) || whole.size() > 4 ||
      fraction.size() > 3)
    return bad("the rate after '@' must be hertz, like 60, 50 or 59.94");
  double hz = 0;
  // from_chars, not stod: the C locale's decimal point whatever the process's.
  std::from_chars(rate.data(), rate.data() + rate.size(), hz);
  if (hz <= 0)
    return bad("the rate after '@' must be more than 0 Hz");
  request.hz = hz;
  request.hz_tolerance = 0.5 * std::pow(10.0, -static_cast<double>(fraction.size()));
  return request;
}

ModeSummary summarise(const drm_mode_modeinfo &mode) {
  ModeSummary summary;
  summary.width = mode.hdisplay;
  summary.height = mode.vdisplay;
  summary.preferred = (mode.type & DRM_MODE_TYPE_PREFERRED) != 0;
  summary.interlaced = (mode.flags & DRM_MODE_FLAG_INTERLACE) != 0;
  if (mode.htotal != 0 && mode.vtotal != 0) {
    double frames = mode.clock * 1000.0; // clock is in kHz
    double lines = static_cast<double>(mode.htotal) * mode.vtotal;
    if (summary.interlaced)
      frames *= 2;
    if ((mode.flags & DRM_MODE_FLAG_DBLSCAN) != 0)
      lines *= 2;
    if (mode.vscan > 1)
      lines *= mode.vscan;
    summary.refresh_hz = frames / lines;
  }
  return summary;
}

std::string describe_mode(const ModeSummary &mode) {
  std::array<char, 32> rate{};
  std::snprintf(rate.data(), rate.size(), "@%.2f", mode.refresh_hz);
  return size_text(mode.width, mode.height) + (mode.interlaced ? "i" : "") + rate.data();
}

std::optional<std::size_t> choose_mode(std::span<const ModeSummary> modes,
                                       const std::optional<ModeRequest> &request,
                                       std::string &error) {
  if (modes.empty()) {
    error = "the connector offers no modes";
    return std::nullopt;
  }
  if (!request) {
    for (std::size_t i = 0; i < modes.size(); ++i)
      if (modes[i].preferred)
        return i;
    return 0;
  }
  std::optional<std::size_t> best;
  // Lower is better: the rate's distance when one was asked, then
  // interlacing, then not being preferred, then a lower rate.
  const auto rank = [&](const ModeSummary &mode) {
    const double distance = request->hz ? std::abs(mode.refresh_hz - *request->hz) : 0.0;
    return std::array<double, 4>{distance, mode.interlaced ? 1.0 : 0.0, mode.preferred ? 0.0 : 1.0,
                                 -mode.refresh_hz};
  };
  for (std::size_t i = 0; i < modes.size(); ++i) {
    const ModeSummary &mode = modes[i];
    if (mode.width != request->width || mode.height != request->height)
      continue;
    if (request->hz && std::abs(mode.refresh_hz - *request->hz) > request->hz_tolerance + 1e-9)
      continue;
    if (!best || rank(mode) < rank(modes[*best]))
      best = i;
  }
  if (!best) {
    std::string asked = size_text(request->width, request->height);
    if (request->hz) {
      std::array<char, 32> rate{};
      std::snprintf(rate.data(), rate.size(), "@%g", *request->hz);
      asked += rate.data();
    }
    error = "no mode " + asked + " among the connector's: " + offered(modes);
  }
  return best;
}

std::optional<Placement> centre_frame(int frame_width, int frame_height, int mode_width,
                                      int mode_height, std::string &error) {
  if (frame_width > mode_width || frame_height > mode_height) {
    error = "the frame, " + size_text(frame_width, frame_height) + ", is larger than the mode, " +
            size_text(mode_width, mode_height) +
            " (frames are shown 1:1, not scaled): render at most the mode's size or choose a "
            "larger mode";
    return std::nullopt;
  }
  return Placement{(mode_width - frame_width) / 2, (mode_height - frame_height) / 2};
}

std::optional<std::uint32_t> choose_crtc(std::uint32_t current_encoder,
                                         std::span<const EncoderSummary> encoders,
                                         std::span<const std::uint32_t> crtcs,
                                         std::span<const std::uint32_t> busy) {
  for (const EncoderSummary &encoder : encoders)
    if (encoder.id == current_encoder && encoder.crtc_id != 0)
      return encoder.crtc_id;
  for (const EncoderSummary &encoder : encoders)
    for (std::size_t i = 0; i < crtcs.size() && i < 32; ++i)
      if ((encoder.possible_crtcs & (1u << i)) != 0 &&
          std::find(busy.begin(), busy.end(), crtcs[i]) == busy.end())
        return crtcs[i];
  return std::nullopt;
}

} // namespace camhead::hal::output::drm
