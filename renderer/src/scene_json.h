// The strict JSON layer under the scene reader: parsing as Python's json
// does, and Checker, which mirrors Checker in
// shared/reference/blender_scene.py check for check, so that the first problem
// reported is the same one the reference reports. Private to the renderer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace camhead::renderer::detail {

// ordered_json keeps the materials in file order; with duplicate keys it
// keeps the first position and the last value, as Python's dict does.
using Json = nlohmann::ordered_json;
using Keys = std::initializer_list<std::string_view>;
using Vec = std::vector<double>;

std::string child(const std::string &field, std::string_view key);
std::string show(double v);

// A finite double that overflows float would turn into inf in the model.
bool fits_float(double v);

bool is_finite_number(const Json &v);

struct Range {
  Range(std::optional<double> lo_ = {}, std::optional<double> hi_ = {}, bool open = false)
      : lo(lo_), hi(hi_), lo_open(open) {}
  std::optional<double> lo, hi;
  bool lo_open;
};

// Each check throws SceneError on the first problem it finds.
class Checker {
public:
  explicit Checker(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string &field, const std::string &reason) const;

  void keys(const Json &d, const std::string &field, Keys required, Keys optional = {}) const;

  double number(const Json &d, std::string_view k, const std::string &field, Range r,
                std::optional<double> def = std::nullopt) const;

  std::int64_t integer(const Json &d, std::string_view k, const std::string &field, std::int64_t lo,
                       std::int64_t hi, std::optional<std::int64_t> def = std::nullopt) const;

  Vec vec(const Json &d, std::string_view k, const std::string &field, std::size_t n = 3,
          Range r = {}, std::optional<Vec> def = std::nullopt, bool nonzero = false) const;

  std::string string(const Json &d, std::string_view k, const std::string &field,
                     std::vector<std::string> choices = {},
                     std::optional<std::string> def = std::nullopt) const;

private:
  void check_range(const std::string &f, double v, const Range &r) const;

  std::string file_;
};

// Parses text as Python's json would, NaN, Infinity and overflowing literals
// included; throws SceneError naming file on a syntax error.
Json parse_json(std::string_view text, const std::string &file);

} // namespace camhead::renderer::detail
