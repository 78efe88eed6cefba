// Quadrature lens encoders wired straight to GPIO lines, read through the
// kernel's GPIO character device with libgpiod 1.6 (what Debian 12 ships).
// libgpiod types stay in src/gpiod_edge_source.h: this header is plain data.
//
// How it works: every configured line is requested for both-edge events
// (consumer "camhead"); the initial levels are read; poll() waits on all line
// fds at once, drains the events, orders them by the kernel's timestamp and
// feeds one QuadratureDecoder per axis (quadrature_encoder.h has the rest).
//
// Limits of the v1 uAPI that libgpiod 1.6 uses, worth knowing when wiring:
//   - Each line has its own event queue of 16 in the kernel. Events of A and B
//     are merged here by timestamp; a queue that overflows drops events
//     silently (see QuadratureDecoder for what a lost edge costs, and the idle
//     re-read that recovers single ones).
//   - The kernel stamps an edge in its hard interrupt handler but reads the
//     level (rising or falling) later in the interrupt thread. Decoding is
//     reliable while edges are further apart than that thread's latency (tens
//     of microseconds on a small ARM board: keep the edge rate on one axis
//     below ~10 kHz). Faster encoders belong on a hardware counter.
//   - Timestamps are CLOCK_MONOTONIC since Linux 5.7 (ktime_get_ns() in
//     drivers/gpio/gpiolib-cdev.c); earlier kernels used CLOCK_REALTIME, which
//     the source detects (a stamp ahead of the monotonic clock by more than a
//     second) and maps back to CLOCK_MONOTONIC.
//
// Thread safety: as QuadratureEncoder (the lens thread only).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "camhead/hal/lens/gpio/quadrature_decoder.h"
#include "camhead/hal/lens/gpio/quadrature_encoder.h"

namespace camhead::hal::lens::gpio {

// Line offsets on the chip, and how the axis decodes.
struct GpioQuadratureAxis {
  unsigned line_a = 0;
  unsigned line_b = 0;
  std::optional<unsigned> line_index;
  bool index_active_low = false; // many encoders pull the index low
  QuadratureAxisConfig decoder;  // reverse, counts_at_index, index_gate, ...
};

enum class GpioBias : std::uint8_t { as_is, disable, pull_up, pull_down };

struct GpioQuadratureConfig {
  // gpiod_chip_open_lookup(): a name ("gpiochip0"), a path ("/dev/gpiochip0"),
  // a number ("0") or a label ("pinctrl-bcm2711"). A label survives the chip
  // being renumbered when it comes back.
  std::string chip = "gpiochip0";
  std::optional<GpioQuadratureAxis> focus, iris, zoom;
  // Open-collector encoder outputs need a pull-up (kernel 5.5 or later).
  GpioBias bias = GpioBias::as_is;
  std::string consumer = "camhead"; // shown by gpioinfo
  std::chrono::milliseconds reopen_interval{1000};
  bool resync_when_idle = true; // QuadratureEncoderOptions::resync_when_idle
};

// Checks the config without touching a device: a chip is named, at least one
// axis is set, no line is used twice, counts_at_index has an index line.
// Returns "" when valid, else one message naming the field:
// "gpio gpiochip0: zoom.line_b 17 is already focus.line_a".
[[nodiscard]] std::string validate(const GpioQuadratureConfig &config);

// Validates, opens the chip and requests the lines. Throws
// std::invalid_argument for an invalid config and std::runtime_error naming
// the chip and line for a missing chip, a line beyond the chip or a line in
// use by someone else ("gpio gpiochip0 line 17 (focus A): cannot request
// both-edge events: Device or resource busy; used by \"foo\"").
[[nodiscard]] std::unique_ptr<QuadratureEncoder>
open_gpio_quadrature(const GpioQuadratureConfig &config);

} // namespace camhead::hal::lens::gpio
