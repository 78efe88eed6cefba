// The allowed range of a number in a configuration file, shared by the JSON
// and CSV readers so that both name it in the same words: "must be within
// 0.5 .. 128", "must be > 0 and <= 10000", "must be >= 0", "must be <= 5".
#pragma once

#include <optional>
#include <string>

namespace camhead::base {

struct Range {
  std::optional<double> lo, hi;
  // lo itself is not allowed: distances, focal lengths, sizes.
  bool lo_open = false;

  [[nodiscard]] static Range within(double lo, double hi) { return {lo, hi, false}; }
  [[nodiscard]] static Range at_least(double lo) { return {lo, std::nullopt, false}; }
  [[nodiscard]] static Range above(double lo, std::optional<double> hi = std::nullopt) {
    return {lo, hi, true};
  }
  [[nodiscard]] static Range at_most(double hi) { return {std::nullopt, hi, false}; }

  [[nodiscard]] bool contains(double v) const;
  // "within 0.5 .. 128", "> 0 and <= 10000", ">= 0", "> 0", "<= 5"; empty
  // when unbounded. Bounds print as an ostream prints a double (1e+06).
  [[nodiscard]] std::string describe() const;
};

} // namespace camhead::base
