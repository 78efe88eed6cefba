// The libusb backend without a board: what every development and CI machine
// sees. It must come up waiting, never block poll() past its timeout, and
// shut down promptly. The board itself is exercised by the VM test
// (tests/vm/usb_vm_check.cpp) and, on the same shared code, by the simulated
// twin's tests.
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "camhead/hal/lens/usb/usb_lens.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

using namespace std::chrono_literals;

bool ends_with(const std::string &s, const std::string &tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// A product id no board answers to, so that a lab machine with a real board
// plugged in still sees "absent".
UsbLensConfig absent_board() {
  UsbLensConfig config;
  config.pid = 0xFFFE;
  config.rescan_interval = 100ms;
  return config;
}

TEST(LibusbLens, AbsentBoardIsNotAnError) {
  const auto lens = open_usb_lens(absent_board());
  ASSERT_NE(lens, nullptr);
  EXPECT_EQ(lens->name(), "usb 1209:fffe");
  const EncoderStatus s = lens->status();
  EXPECT_FALSE(s.connected);
  EXPECT_EQ(s.readings, 0u);
  // "not connected, waiting", or where there is no USB at all, why libusb
  // could not start; always naming the device and always waiting.
  EXPECT_EQ(s.detail.rfind("usb 1209:fffe: ", 0), 0u) << s.detail;
  EXPECT_TRUE(ends_with(s.detail, ", waiting")) << s.detail;
}

TEST(LibusbLens, PollHonoursItsTimeoutWhileWaiting) {
  const auto lens = open_usb_lens(absent_board());
  std::vector<EncoderReading> out;
  for (int i = 0; i < 5; ++i) { // across several rescans
    const auto t0 = std::chrono::steady_clock::now();
    lens->poll(50ms, out);
    const auto waited = std::chrono::steady_clock::now() - t0;
    EXPECT_GE(waited, 49ms);
    EXPECT_LT(waited, 500ms);
  }
  EXPECT_TRUE(out.empty());
  const EncoderStatus s = lens->status();
  EXPECT_FALSE(s.connected);
  EXPECT_EQ(s.reconnects, 0u);
  EXPECT_TRUE(ends_with(s.detail, ", waiting")) << s.detail;
}

TEST(LibusbLens, ShutsDownPromptly) {
  for (int i = 0; i < 3; ++i) {
    auto lens = open_usb_lens(absent_board());
    std::this_thread::sleep_for(20ms);
    const auto t0 = std::chrono::steady_clock::now();
    lens.reset();
    EXPECT_LT(std::chrono::steady_clock::now() - t0, 500ms);
  }
}

TEST(LibusbLens, NameCarriesTheSerial) {
  UsbLensConfig config;
  config.serial = "LE000042";
  EXPECT_EQ(usb_lens_name(config), "usb 1209:0001 serial LE000042");
  EXPECT_EQ(usb_lens_name({}), "usb 1209:0001");
}

} // namespace
} // namespace camhead::hal::lens
