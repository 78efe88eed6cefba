// The DRM sink's pure decisions: card names, connector names, mode strings,
// the mode choice, centring and the CRTC choice (drm_modes.h). The lab
// (tests/vm, vm.drm_*) runs the sink itself on QEMU's bochs display.
#include <vector>

#include "drm_modes.h"

#include <gtest/gtest.h>

namespace camhead::hal::output::drm {
namespace {

TEST(DrmCardSpec, PathsNodeNamesAndDriverNames) {
  EXPECT_EQ(classify_card("/dev/dri/card1").kind, CardSpec::Kind::path);
  EXPECT_EQ(classify_card("/dev/dri/card1").value, "/dev/dri/card1");
  EXPECT_EQ(classify_card("./card0").kind, CardSpec::Kind::path);
  const CardSpec node = classify_card("card0");
  EXPECT_EQ(node.kind, CardSpec::Kind::path);
  EXPECT_EQ(node.value, "/dev/dri/card0");
  EXPECT_EQ(classify_card("card12").value, "/dev/dri/card12");
  const CardSpec driver = classify_card("bochs-drm");
  EXPECT_EQ(driver.kind, CardSpec::Kind::driver);
  EXPECT_EQ(driver.value, "bochs-drm");
  // Not a node name: a driver that happens to start with "card".
  EXPECT_EQ(classify_card("cardx").kind, CardSpec::Kind::driver);
  EXPECT_EQ(classify_card("card").kind, CardSpec::Kind::driver);
}

TEST(DrmConnectorName, AsTheKernelSpellsIt) {
  EXPECT_EQ(connector_name(DRM_MODE_CONNECTOR_HDMIA, 1), "HDMI-A-1");
  EXPECT_EQ(connector_name(DRM_MODE_CONNECTOR_VIRTUAL, 1), "Virtual-1");
  EXPECT_EQ(connector_name(DRM_MODE_CONNECTOR_DisplayPort, 2), "DP-2");
  EXPECT_EQ(connector_name(DRM_MODE_CONNECTOR_eDP, 1), "eDP-1");
  EXPECT_EQ(connector_name(DRM_MODE_CONNECTOR_9PinDIN, 1), "DIN-1");
  EXPECT_EQ(connector_name(DRM_MODE_CONNECTOR_USB, 3), "USB-3");
  EXPECT_EQ(connector_name(99, 1), "type99-1");
  EXPECT_EQ(connection_name(1), "connected");
  EXPECT_EQ(connection_name(2), "disconnected");
  EXPECT_EQ(connection_name(3), "unknown");
}

TEST(DrmModeSpec, SizeAndOptionalRate) {
  std::string error;
  const auto plain = parse_mode_spec("1920x1080", error);
  ASSERT_TRUE(plain) << error;
  EXPECT_EQ(plain->width, 1920);
  EXPECT_EQ(plain->height, 1080);
  EXPECT_FALSE(plain->hz);

  const auto whole = parse_mode_spec("1280x800@60", error);
  ASSERT_TRUE(whole) << error;
  EXPECT_DOUBLE_EQ(*whole->hz, 60);
  EXPECT_DOUBLE_EQ(whole->hz_tolerance, 0.5);

  const auto ntsc = parse_mode_spec("1920x1080@59.94", error);
  ASSERT_TRUE(ntsc) << error;
  EXPECT_DOUBLE_EQ(*ntsc->hz, 59.94);
  EXPECT_NEAR(ntsc->hz_tolerance, 0.005, 1e-12);
}

TEST(DrmModeSpec, RejectsWhatIsNotWxHAtHz) {
  for (const char *bad : {"", "1920", "1920x", "x1080", "0x1080", "1920x-1", "1920x1080p",
                          "1920 x 1080", "1920x1080@", "1920x1080@abc", "1920x1080@0",
                          "1920x1080@60Hz", "1920x1080@-60", "1920x1080@.5", "1920x1080@60."}) {
    std::string error;
    EXPECT_FALSE(parse_mode_spec(bad, error)) << bad;
    EXPECT_NE(error.find(std::string("'") + bad + "'"), std::string::npos) << error;
  }
}

// Timings from the kernel's CEA/DMT tables (clock in kHz).
drm_mode_modeinfo timing(int w, int h, int clock, int htotal, int vtotal, bool preferred = false,
                         bool interlaced = false) {
  drm_mode_modeinfo mode{};
  mode.hdisplay = static_cast<__u16>(w);
  mode.vdisplay = static_cast<__u16>(h);
  mode.clock = static_cast<__u32>(clock);
  mode.htotal = static_cast<__u16>(htotal);
  mode.vtotal = static_cast<__u16>(vtotal);
  mode.type = preferred ? DRM_MODE_TYPE_PREFERRED : 0;
  mode.flags = interlaced ? DRM_MODE_FLAG_INTERLACE : 0;
  return mode;
}

TEST(DrmModeSummary, RefreshFromTimings) {
  EXPECT_NEAR(summarise(timing(1920, 1080, 148500, 2200, 1125)).refresh_hz, 60.0, 1e-9);
  EXPECT_NEAR(summarise(timing(1920, 1080, 148352, 2200, 1125)).refresh_hz, 59.94, 0.001);
  EXPECT_NEAR(summarise(timing(1920, 1080, 148500, 2640, 1125)).refresh_hz, 50.0, 1e-9);
  // Interlaced: two fields per frame time, the rate counts fields.
  const ModeSummary interlaced = summarise(timing(1920, 1080, 74250, 2200, 1125, false, true));
  EXPECT_TRUE(interlaced.interlaced);
  EXPECT_NEAR(interlaced.refresh_hz, 60.0, 1e-9);
  EXPECT_EQ(describe_mode(interlaced), "1920x1080i@60.00");
  EXPECT_EQ(summarise(timing(1, 1, 1, 0, 0)).refresh_hz, 0);
  EXPECT_TRUE(summarise(timing(1280, 800, 83500, 1680, 831, true)).preferred);
}

std::vector<ModeSummary> hdmi_monitor() {
  return {
      summarise(timing(1920, 1080, 148500, 2200, 1125, true)),       // 0: 60, preferred
      summarise(timing(1920, 1080, 148500, 2640, 1125)),             // 1: 50
      summarise(timing(1920, 1080, 148352, 2200, 1125)),             // 2: 59.94
      summarise(timing(1920, 1080, 74250, 2200, 1125, false, true)), // 3: 60i
      summarise(timing(1280, 720, 74250, 1980, 750)),                // 4: 50
      summarise(timing(1280, 720, 74250, 1650, 750)),                // 5: 60
  };
}

std::optional<std::size_t> pick(const std::vector<ModeSummary> &modes, const char *spec,
                                std::string &error) {
  if (spec == nullptr)
    return choose_mode(modes, std::nullopt, error);
  const std::optional<ModeRequest> request = parse_mode_spec(spec, error);
  EXPECT_TRUE(request) << error;
  return choose_mode(modes, request, error);
}

TEST(DrmModeChoice, PreferredWhenNoneAsked) {
  std::string error;
  EXPECT_EQ(pick(hdmi_monitor(), nullptr, error), 0u);
  // No preferred flag: the kernel's first.
  std::vector<ModeSummary> modes = hdmi_monitor();
  modes[0].preferred = false;
  EXPECT_EQ(pick(modes, nullptr, error), 0u);
  std::swap(modes[0], modes[4]);
  modes[2].preferred = true;
  EXPECT_EQ(pick(modes, nullptr, error), 2u);
}

TEST(DrmModeChoice, SizeThenRateToThePrecisionWritten) {
  std::string error;
  const std::vector<ModeSummary> modes = hdmi_monitor();
  EXPECT_EQ(pick(modes, "1920x1080", error), 0u); // progressive, preferred
  EXPECT_EQ(pick(modes, "1920x1080@50", error), 1u);
  EXPECT_EQ(pick(modes, "1920x1080@60", error), 0u); // 60.00 is nearer than 59.94
  EXPECT_EQ(pick(modes, "1920x1080@59.94", error), 2u);
  EXPECT_EQ(pick(modes, "1920x1080@59.9", error), 2u);
  EXPECT_EQ(pick(modes, "1280x720", error), 5u); // the higher rate
  EXPECT_EQ(pick(modes, "1280x720@50", error), 4u);
}

TEST(DrmModeChoice, NoMatchNamesWhatWasAskedAndWhatThereIs) {
  std::string error;
  const std::vector<ModeSummary> modes = hdmi_monitor();
  EXPECT_FALSE(pick(modes, "1920x1080@30", error));
  EXPECT_NE(error.find("no mode 1920x1080@30 "), std::string::npos) << error;
  EXPECT_NE(error.find("1920x1080@60.00 (preferred)"), std::string::npos) << error;
  EXPECT_NE(error.find("1280x720@50.00"), std::string::npos) << error;
  EXPECT_FALSE(pick(modes, "1920x1080@60.5", error)); // 60.5 +- 0.05 holds neither
  EXPECT_FALSE(pick(modes, "3840x2160", error));
  EXPECT_NE(error.find("no mode 3840x2160 "), std::string::npos) << error;
  EXPECT_FALSE(choose_mode({}, std::nullopt, error));
  EXPECT_NE(error.find("no modes"), std::string::npos) << error;
}

TEST(DrmCentring, CentredRoundedDownAndRefusedWhenLarger) {
  std::string error;
  const auto pal = centre_frame(720, 576, 1920, 1080, error);
  ASSERT_TRUE(pal);
  EXPECT_EQ(pal->x, 600);
  EXPECT_EQ(pal->y, 252);
  const auto lab = centre_frame(640, 480, 1280, 800, error);
  ASSERT_TRUE(lab);
  EXPECT_EQ(lab->x, 320);
  EXPECT_EQ(lab->y, 160);
  const auto odd = centre_frame(641, 479, 1280, 800, error);
  ASSERT_TRUE(odd);
  EXPECT_EQ(odd->x, 319);
  EXPECT_EQ(odd->y, 160);
  const auto same = centre_frame(1280, 800, 1280, 800, error);
  ASSERT_TRUE(same);
  EXPECT_EQ(same->x, 0);
  EXPECT_EQ(same->y, 0);

  EXPECT_FALSE(centre_frame(1920, 1080, 1280, 800, error));
  EXPECT_NE(error.find("1920x1080"), std::string::npos) << error;
  EXPECT_NE(error.find("1280x800"), std::string::npos) << error;
  EXPECT_FALSE(centre_frame(1281, 10, 1280, 800, error)); // wider only
  EXPECT_FALSE(centre_frame(10, 801, 1280, 800, error));  // taller only
}

TEST(DrmCrtcChoice, CurrentEncodersCrtcFirst) {
  const std::vector<std::uint32_t> crtcs = {31, 32};
  const std::vector<EncoderSummary> encoders = {{40, 32, 0b11}};
  EXPECT_EQ(choose_crtc(40, encoders, crtcs, {}), 32u);
  // Already ours even when listed busy (its other connectors are restored too).
  const std::vector<std::uint32_t> busy = {32};
  EXPECT_EQ(choose_crtc(40, encoders, crtcs, busy), 32u);
}

TEST(DrmCrtcChoice, FirstFreePossibleCrtcOtherwise) {
  const std::vector<std::uint32_t> crtcs = {31, 32, 33};
  const std::vector<EncoderSummary> encoders = {{40, 0, 0b110}, {41, 0, 0b001}};
  EXPECT_EQ(choose_crtc(0, encoders, crtcs, {}), 32u);
  const std::vector<std::uint32_t> busy32 = {32};
  EXPECT_EQ(choose_crtc(0, encoders, crtcs, busy32), 33u);
  const std::vector<std::uint32_t> busy_all = {31, 32, 33};
  EXPECT_FALSE(choose_crtc(0, encoders, crtcs, busy_all));
  EXPECT_FALSE(choose_crtc(0, {}, crtcs, {}));
  // A current encoder that feeds nothing does not count.
  const std::vector<EncoderSummary> idle = {{40, 0, 0b001}};
  EXPECT_EQ(choose_crtc(40, idle, crtcs, {}), 31u);
}

} // namespace
} // namespace camhead::hal::output::drm
