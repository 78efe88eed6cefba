// ConfigError, the reading of a configuration file, and the words of a range.
#include "camhead/base/config_error.h"

#include <sstream>

#include "camhead/base/config_range.h"
#include "camhead/base/input_file.h"
#include "config_words.h"

namespace camhead::base {

ConfigError::ConfigError(std::string file, std::string field, std::string reason)
    : ConfigError(std::move(file), 0, std::move(field), std::move(reason)) {}

ConfigError::ConfigError(std::string file, int line, std::string field, std::string reason)
    : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : "") + ": " +
                         (field.empty() ? "" : field + ": ") + reason),
      file_(std::move(file)), line_(line), field_(std::move(field)), reason_(std::move(reason)) {}

std::string read_config_file(const std::filesystem::path &path) {
  std::string error;
  std::optional<std::string> text = read_input_file(path, kMaxConfigFileBytes, error);
  if (!text)
    throw ConfigError(path.string(), "(file)", error);
  return std::move(*text);
}

bool Range::contains(double v) const {
  if (lo && (lo_open ? !(v > *lo) : !(v >= *lo)))
    return false;
  return !(hi && v > *hi);
}

std::string Range::describe() const {
  const std::string low = lo ? (lo_open ? "> " : ">= ") + detail::show(*lo) : "";
  if (!hi)
    return low;
  if (!lo)
    return "<= " + detail::show(*hi);
  if (!lo_open)
    return "within " + detail::show(*lo) + " .. " + detail::show(*hi);
  return low + " and <= " + detail::show(*hi);
}

namespace detail {

std::string show(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string integer_reason(std::int64_t lo, std::int64_t hi) {
  return "must be an integer within " + std::to_string(lo) + " .. " + std::to_string(hi);
}

} // namespace detail

} // namespace camhead::base
