// The decisions the DRM sink makes from what the card reports, as pure
// functions (tests/hal/output/drm): which card a name means, what a connector is
// called, which mode a "WxH[@Hz]" string picks, where the frame sits in the
// mode, which CRTC drives the connector.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <drm_mode.h>

namespace camhead::hal::output::drm {

// --- Cards ---------------------------------------------------------------------
// DrmSinkOptions::card: a path (anything with a '/'), a node name under
// /dev/dri ("card0"), or else a driver name ("bochs-drm").
struct CardSpec {
  enum class Kind { path, driver };
  Kind kind = Kind::path;
  std::string value; // the path, or the driver's name
};
[[nodiscard]] CardSpec classify_card(std::string_view card);

// --- Connectors ----------------------------------------------------------------
// The kernel's name for a connector: its type as drm_connector.c spells it and
// its number among connectors of that type ("HDMI-A-1", "Virtual-1").
[[nodiscard]] std::string connector_name(std::uint32_t type, std::uint32_t type_id);
// "connected", "disconnected", "unknown" (DRM_MODE_CONNECTED = 1, ...).
[[nodiscard]] std::string_view connection_name(std::uint32_t connection);

// --- Modes ---------------------------------------------------------------------
// What DrmSinkOptions::mode asks for. `hz_tolerance` is half a unit of the
// last digit written: "@60" is 60 +- 0.5, "@59.94" is 59.94 +- 0.005.
struct ModeRequest {
  int width = 0;
  int height = 0;
  std::optional<double> hz;
  double hz_tolerance = 0;
};
// Empty with `error` for anything but "WxH" or "WxH@Hz" with positive numbers.
[[nodiscard]] std::optional<ModeRequest> parse_mode_spec(std::string_view spec, std::string &error);

// One mode of a connector, as the choice needs it.
struct ModeSummary {
  int width = 0;
  int height = 0;
  double refresh_hz = 0;
  bool preferred = false;
  bool interlaced = false;
};
// The refresh rate from the timings, as the kernel's drm_mode_vrefresh()
// computes it but unrounded (vrefresh itself is rounded to whole hertz).
[[nodiscard]] ModeSummary summarise(const drm_mode_modeinfo &mode);
// "1280x800@60.00" (with an "i" after the height for interlaced modes).
[[nodiscard]] std::string describe_mode(const ModeSummary &mode);

// The index of the mode to use. No request: the first preferred mode, else the
// first (the kernel lists the preferred first). A request: modes of that size;
// with a rate, the nearest within its tolerance; without, progressive before
// interlaced, then the preferred, then the highest rate. Empty with `error`
// naming what was asked and every mode offered.
[[nodiscard]] std::optional<std::size_t> choose_mode(std::span<const ModeSummary> modes,
                                                     const std::optional<ModeRequest> &request,
                                                     std::string &error);

// Where a frame sits in the mode: centred, rounded down to whole pixels. Empty
// with `error` naming both sizes when the frame is wider or taller.
struct Placement {
  int x = 0;
  int y = 0;
};
[[nodiscard]] std::optional<Placement> centre_frame(int frame_width, int frame_height,
                                                    int mode_width, int mode_height,
                                                    std::string &error);

// --- CRTCs ---------------------------------------------------------------------
struct EncoderSummary {
  std::uint32_t id = 0;
  std::uint32_t crtc_id = 0;        // the CRTC it feeds now, 0 for none
  std::uint32_t possible_crtcs = 0; // bit i: the i-th CRTC of GETRESOURCES
};
// The CRTC for a connector, as kmscube chooses it: the one its current encoder
// feeds; else, over its encoders in order, the first CRTC they can use that
// drives no other connector (`busy`). Empty when there is none.
[[nodiscard]] std::optional<std::uint32_t> choose_crtc(std::uint32_t current_encoder,
                                                       std::span<const EncoderSummary> encoders,
                                                       std::span<const std::uint32_t> crtcs,
                                                       std::span<const std::uint32_t> busy);

} // namespace camhead::hal::output::drm
