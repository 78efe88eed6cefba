// The scripted lens trajectory that the simulated board, the VM test's
// FunctionFS gadget and the VM checker share: each axis a linear ramp in the
// report index (the n-th report since the board powered up).
//
// Why a ramp in the index and not in time: a reader that sees only counts
// (EncoderReading has no sequence number) can recover the index from any one
// reading and check the other two axes against it, and two consecutive
// readings must be consecutive indices unless a report was lost. That makes
// "the counts match the script" an exact check, even under emulation where
// the timing is anything but exact.
//
// Pure and constexpr; any thread.
#pragma once

#include <cstdint>
#include <optional>

namespace camhead::hal::lens {

struct LensAxes {
  std::int32_t focus = 0, iris = 0, zoom = 0;

  bool operator==(const LensAxes &) const = default;
};

struct LensRamp {
  // Distinct starts and steps (one falling) so that swapped axes or a wrong
  // sign show; small enough not to wrap within 10^6 reports.
  std::int32_t focus0 = 1000, focus_step = 10;
  std::int32_t iris0 = 50000, iris_step = -3;
  std::int32_t zoom0 = -20000, zoom_step = 7;

  [[nodiscard]] constexpr LensAxes at(std::uint32_t index) const {
    return LensAxes{ramp(focus0, focus_step, index), ramp(iris0, iris_step, index),
                    ramp(zoom0, zoom_step, index)};
  }

  // The index whose counts these are; empty when no index gives all three
  // (a corrupted or foreign reading). Needs focus_step != 0.
  [[nodiscard]] constexpr std::optional<std::uint32_t> index_of(const LensAxes &axes) const {
    if (focus_step == 0) {
      return std::nullopt;
    }
    const std::int64_t diff = std::int64_t{axes.focus} - focus0;
    if (diff % focus_step != 0 || diff / focus_step < 0 || diff / focus_step > 0xFFFFFFFF) {
      return std::nullopt;
    }
    const auto index = static_cast<std::uint32_t>(diff / focus_step);
    if (at(index) != axes) {
      return std::nullopt;
    }
    return index;
  }

private:
  // In 64 bits, then to int32 modulo 2^32 (defined since C++20): no overflow.
  static constexpr std::int32_t ramp(std::int32_t start, std::int32_t step, std::uint32_t i) {
    return static_cast<std::int32_t>(
        static_cast<std::uint32_t>(std::int64_t{start} + std::int64_t{step} * std::int64_t{i}));
  }
};

} // namespace camhead::hal::lens
