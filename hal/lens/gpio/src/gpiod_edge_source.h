// The libgpiod 1.6 edge source: with gpiod_library.h, the only header of
// camhead that includes <gpiod.h> (style.md: gpiod types never leave the
// module). libgpiod is opened at run time (gpiod_library.h). See
// gpio_quadrature.h for the behaviour of the v1 uAPI behind it.
//
// Handles: the chip is owned by a unique_ptr with gpiod_chip_close as its
// deleter; the gpiod_line pointers are borrowed from the chip, which releases
// every requested line when it closes. So close() is "reset the chip", and an
// open() that fails halfway leaves nothing requested.
//
// Thread safety: none; the lens thread owns it through QuadratureEncoder.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camhead/base/realtime_stamp.h"
#include "camhead/hal/lens/gpio/edge_source.h"
#include "camhead/hal/lens/gpio/gpio_quadrature.h"
#include "gpiod_library.h"

namespace camhead::hal::lens::gpio::detail {

struct ChipCloser {
  void operator()(gpiod_chip *chip) const noexcept { gpiod().chip_close(chip); }
};
using ChipHandle = std::unique_ptr<gpiod_chip, ChipCloser>;

// What one requested line is for.
struct LineRole {
  LensAxis axis = LensAxis::focus;
  QuadratureLine line = QuadratureLine::a;
  unsigned offset = 0;
  bool active_low = false;
};

class GpiodEdgeSource final : public EdgeSource {
public:
  // Takes a validated config (validate() returned ""); opens nothing yet.
  explicit GpiodEdgeSource(const GpioQuadratureConfig &config);
  ~GpiodEdgeSource() override = default;

  [[nodiscard]] std::string name() const override { return "gpio " + chip_descr_; }
  [[nodiscard]] AxisSet axes() const override { return axes_; }
  [[nodiscard]] bool open(std::string &error) override;
  void close() override;
  [[nodiscard]] bool read_levels(AllLevels &levels, std::int64_t &t_ns,
                                 std::string &error) override;
  [[nodiscard]] bool wait_edges(std::chrono::milliseconds timeout, std::vector<EdgeEvent> &out,
                                std::string &error) override;

private:
  // "gpio gpiochip0 line 17 (focus A)"; with a label as descriptor,
  // "gpio my-label (gpiochip3) line 17 (focus A)".
  [[nodiscard]] std::string line_name(const LineRole &role) const;
  // The events of the lines `ready`, their realtime stamps moved by
  // `clocks` (read at the first such stamp of the wait_edges() call).
  [[nodiscard]] bool read_ready(gpiod_line_bulk &ready, std::optional<base::ClockPair> &clocks,
                                std::vector<EdgeEvent> &out, std::string &error);
  // The kernel's stamp in CLOCK_MONOTONIC ns; `now_ns` is that clock now.
  // A realtime stamp (kernels before 5.7) is moved by `clocks`, read at the
  // first such stamp of a wait_edges() call and kept for the rest of it, so
  // that one offset moves them all and their order holds.
  [[nodiscard]] static std::int64_t to_monotonic_ns(const timespec &ts, std::int64_t now_ns,
                                                    std::optional<base::ClockPair> &clocks);

  std::string chip_descr_;
  std::string consumer_;
  int request_flags_ = 0;
  AxisSet axes_{};
  std::vector<LineRole> roles_;

  ChipHandle chip_;
  std::string chip_name_;                     // the kernel's name of the open chip
  std::vector<gpiod_line *> lines_;           // parallel to roles_; borrowed from chip_
  std::array<gpiod_line_event, 16> buffer_{}; // the kernel queues 16 per line
};

} // namespace camhead::hal::lens::gpio::detail
