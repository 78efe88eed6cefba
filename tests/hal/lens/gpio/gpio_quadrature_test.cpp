// The libgpiod backend where no GPIO hardware is needed: config checks and
// the error for a chip that is not there. Against a real kernel driver
// (gpio-sim) it runs in the QEMU hardware lab (tests/vm); here a real chip is
// used only when CAMHEAD_TEST_GPIOCHIP names one, else that test skips.
#include <chrono>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/hal/lens/gpio/gpio_quadrature.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens::gpio {
namespace {

using namespace std::chrono_literals;

GpioQuadratureAxis lines(unsigned a, unsigned b, std::optional<unsigned> index = {}) {
  GpioQuadratureAxis axis;
  axis.line_a = a;
  axis.line_b = b;
  axis.line_index = index;
  return axis;
}

GpioQuadratureConfig two_axes() {
  GpioQuadratureConfig c;
  c.chip = "gpiochip0";
  c.focus = lines(17, 18, 19);
  c.zoom = lines(20, 21);
  return c;
}

TEST(GpioQuadratureConfig, ValidConfigPasses) {
  EXPECT_EQ(validate(two_axes()), "");
}

TEST(GpioQuadratureConfig, LineUsedTwiceNamesBothFields) {
  GpioQuadratureConfig c = two_axes();
  c.zoom->line_b = 17;
  EXPECT_EQ(validate(c), "gpio gpiochip0: zoom.line_b 17 is already focus.line_a");
  c = two_axes();
  c.focus->line_index = 18;
  EXPECT_EQ(validate(c), "gpio gpiochip0: focus.line_index 18 is already focus.line_b");
}

TEST(GpioQuadratureConfig, HomingNeedsAnIndexLine) {
  GpioQuadratureConfig c = two_axes();
  c.zoom->decoder.counts_at_index = 100;
  const std::string e = validate(c);
  EXPECT_NE(e.find("zoom.decoder.counts_at_index"), std::string::npos) << e;
  EXPECT_NE(e.find("zoom.line_index"), std::string::npos) << e;
  c = two_axes();
  c.zoom->decoder.index_gate = IndexGate::ab11;
  EXPECT_NE(validate(c).find("zoom.decoder.index_gate"), std::string::npos);
}

TEST(GpioQuadratureConfig, NeedsAChipAndAnAxis) {
  GpioQuadratureConfig c = two_axes();
  c.chip.clear();
  EXPECT_NE(validate(c).find("chip is empty"), std::string::npos);
  c = GpioQuadratureConfig{};
  EXPECT_EQ(validate(c),
            "gpio gpiochip0: no axis configured; set at least one of focus, iris, zoom");
  c = two_axes();
  c.reopen_interval = 0ms;
  EXPECT_NE(validate(c).find("reopen_interval"), std::string::npos);
}

TEST(GpioQuadratureOpen, InvalidConfigThrowsInvalidArgument) {
  GpioQuadratureConfig c = two_axes();
  c.zoom->line_a = 18;
  EXPECT_THROW((void)open_gpio_quadrature(c), std::invalid_argument);
}

TEST(GpioQuadratureOpen, MissingChipIsNamed) {
  GpioQuadratureConfig c = two_axes();
  c.chip = "camhead-no-such-chip";
  try {
    (void)open_gpio_quadrature(c);
    FAIL() << "opened a chip that does not exist";
  } catch (const std::runtime_error &e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("gpio camhead-no-such-chip: cannot open chip: ", 0), 0u) << what;
  }
}

// CAMHEAD_TEST_GPIOCHIP=gpiochipN (optionally CAMHEAD_TEST_GPIO_LINES=A,B):
// a chip whose two lines are free. Opens them, polls, checks the state.
TEST(GpioQuadratureHardware, OpensANamedChip) {
  const char *chip = std::getenv("CAMHEAD_TEST_GPIOCHIP");
  if (chip == nullptr || *chip == '\0') {
    GTEST_SKIP() << "set CAMHEAD_TEST_GPIOCHIP to a chip with free lines 0 and 1 to run this";
  }
  GpioQuadratureConfig c;
  c.chip = chip;
  c.focus = lines(0, 1);
  auto encoder = open_gpio_quadrature(c);
  std::vector<EncoderReading> out;
  encoder->poll(10ms, out);
  ASSERT_EQ(out.size(), 1u); // the connect reading
  EXPECT_EQ(out[0].focus, 0);
  const EncoderStatus s = encoder->status();
  EXPECT_TRUE(s.connected) << s.detail;
  EXPECT_EQ(encoder->name(), std::string("gpio ") + chip);
}

} // namespace
} // namespace camhead::hal::lens::gpio
