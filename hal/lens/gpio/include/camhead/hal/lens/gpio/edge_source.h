// Where quadrature edges come from. A GPIO quadrature encoder is three parts:
// an edge source (this interface), one QuadratureDecoder per axis, and the
// reading assembly in QuadratureEncoder. Only the source differs between the
// real backend (libgpiod, src/gpiod_edge_source.h) and the simulated twin
// (simulated_quadrature.h), so the twin exercises the same decoding,
// coalescing and reconnect code as the hardware.
//
// A source never throws once constructed: failures come back as `false` plus
// a message naming the chip and line, and the encoder closes and reopens it.
//
// Thread safety: none; the lens thread owns the source through its encoder.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "camhead/hal/lens/gpio/quadrature_decoder.h"
#include "camhead/hal/lens/monotonic_clock.h"

namespace camhead::hal::lens::gpio {

enum class LensAxis : std::uint8_t { focus, iris, zoom };
inline constexpr std::size_t kLensAxisCount = 3;

[[nodiscard]] constexpr const char *to_string(LensAxis axis) {
  switch (axis) {
  case LensAxis::focus:
    return "focus";
  case LensAxis::iris:
    return "iris";
  case LensAxis::zoom:
    return "zoom";
  }
  return "?";
}

// One edge: `line` of `axis` reads `level` since `t_ns` (CLOCK_MONOTONIC
// nanoseconds, the kernel's own timestamp where there is one). 16 bytes.
struct EdgeEvent {
  std::int64_t t_ns = 0;
  LensAxis axis = LensAxis::focus;
  QuadratureLine line = QuadratureLine::a;
  bool level = false;

  bool operator==(const EdgeEvent &) const = default;
};

using AxisSet = std::array<bool, kLensAxisCount>;
using AllLevels = std::array<AxisLevels, kLensAxisCount>;

class EdgeSource {
public:
  virtual ~EdgeSource() = default;
  EdgeSource() = default;
  EdgeSource(const EdgeSource &) = delete;
  EdgeSource &operator=(const EdgeSource &) = delete;

  // For messages: "gpio gpiochip0", "gpio sim".
  [[nodiscard]] virtual std::string name() const = 0;
  // The axes this source has lines for; fixed at construction.
  [[nodiscard]] virtual AxisSet axes() const = 0;

  // Opens (or reopens) the device and requests the lines. On failure returns
  // false with `error` naming the chip and line; the source is then closed.
  [[nodiscard]] virtual bool open(std::string &error) = 0;
  // Releases everything open() took. Safe to call when closed.
  virtual void close() = 0;

  // Reads the current levels of every line of every axis (false for axes and
  // index lines it does not have) and the CLOCK_MONOTONIC time of the read.
  [[nodiscard]] virtual bool read_levels(AllLevels &levels, std::int64_t &t_ns,
                                         std::string &error) = 0;

  // Waits at most `timeout` for edges and appends every edge available then
  // to `out`, ordered by time. Appending nothing means the wait timed out.
  // Returns false when the device failed (unplugged, chip removed); edges
  // read before the failure are still appended.
  [[nodiscard]] virtual bool wait_edges(std::chrono::milliseconds timeout,
                                        std::vector<EdgeEvent> &out, std::string &error) = 0;

  // The clock the encoder uses to pace reopen attempts, and its sleep while
  // no device is open. CLOCK_MONOTONIC by default; the simulated twin can run
  // on a virtual clock instead so that tests never sleep.
  [[nodiscard]] virtual std::int64_t now_ns() const;
  virtual void sleep_for(std::chrono::nanoseconds duration);
};

} // namespace camhead::hal::lens::gpio
