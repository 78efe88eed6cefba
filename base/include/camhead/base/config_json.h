// The strict JSON reader under the scene, lens-profile and board readers.
// JsonFile parses a file's text; JsonValue is one value in it together with
// its place (the file, and the field path such as "lens.sources[1].port"),
// so that every check below can fail with ConfigError("FILE: FIELD: REASON")
// on the first problem without the caller spelling the path out.
//
// Parsing follows Python's json, which the scene format's reference reader
// (shared/reference/blender_scene.py) uses: NaN, Infinity, -Infinity and
// number literals beyond the double range are read, and then refused as "must
// be a finite number" on their field; objects keep their members in file
// order. Unlike Python's json, a key given twice in one object is an error on
// its field (Python keeps the last value without a word).
// A syntax error is reported on the field "(JSON)" with its line and column.
//
// Values are only looked at, never converted implicitly: nlohmann's own
// exceptions (type_error, out_of_range) never leave this reader.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "camhead/base/config_error.h"
#include "camhead/base/config_range.h"

namespace camhead::base {

using Json = nlohmann::ordered_json;
using Keys = std::vector<std::string_view>;

class JsonFile;

// Copies are cheap enough for configuration files (a pointer and a path);
// a JsonValue must not outlive its JsonFile.
class JsonValue {
public:
  [[nodiscard]] const Json &json() const { return *value_; }
  // The path of this value; empty for the top level.
  [[nodiscard]] const std::string &field() const { return field_; }
  [[nodiscard]] const std::string &file() const;
  // Throws ConfigError on this field ("(top level)" for the root).
  [[noreturn]] void fail(const std::string &reason) const;
  // Throws ConfigError on the member `key`, present or not: for a rule that
  // joins fields (a default "up" parallel to the view, a duplicate name).
  [[noreturn]] void fail_member(std::string_view key, const std::string &reason) const;

  // Members of an object. at() fails on the member's field with "missing"
  // (and ", hint" in parentheses) when this is no object or lacks the key:
  // a tagged value such as {"type": ...} that is no object lacks its tag.
  [[nodiscard]] bool has(std::string_view key) const;
  [[nodiscard]] JsonValue at(std::string_view key, std::string_view hint = {}) const;
  [[nodiscard]] std::optional<JsonValue> find(std::string_view key) const;
  // Fails "must be an object" unless this is one; in file order.
  [[nodiscard]] std::vector<std::pair<std::string, JsonValue>> members() const;

  // Elements of an array: "must be an array" or "must be an array of WHAT".
  [[nodiscard]] std::vector<JsonValue> elements(std::string_view what = {}) const;

  // The checks. Each returns the value or fails on this field.
  //
  // An object whose members are all in `required` or `optional`: "must be an
  // object", then "missing" on the first required key absent, then "unknown
  // field" on the first other key, in file order.
  const JsonValue &object(const Keys &required, const Keys &optional = {}) const;
  // "must be a non-empty string".
  [[nodiscard]] std::string string() const;
  // One of `choices`: "must be one of a, b, c".
  [[nodiscard]] std::string string(const Keys &choices) const;
  // Any string, empty included: "must be a string".
  [[nodiscard]] std::string text() const;
  // "must be true or false".
  [[nodiscard]] bool boolean() const;
  // "must be a finite number", then "must be " + range.describe().
  [[nodiscard]] double number(const Range &range = {}) const;
  // A JSON integer (8.0 is not one) in [lo, hi]: "must be an integer within
  // LO .. HI" for anything else, 1e999 and 400-digit literals included.
  [[nodiscard]] std::int64_t integer(std::int64_t lo, std::int64_t hi) const;
  // "must be an array of N finite numbers", then "components must be " +
  // range.describe().
  [[nodiscard]] std::vector<double> numbers(std::size_t n, const Range &range = {}) const;
  // A non-empty string naming a file, without a NUL or another control
  // character (path_text.h); a relative one is taken relative to
  // the folder of the file it is written in, made absolute so that it does
  // not depend on the working directory when it is opened later.
  [[nodiscard]] std::filesystem::path path() const;

private:
  friend class JsonFile;
  JsonValue(const JsonFile *file, const Json *value, std::string field)
      : file_(file), value_(value), field_(std::move(field)) {}

  const JsonFile *file_;
  const Json *value_;
  std::string field_;
};

// A parsed configuration file. Neither copied nor moved: its values point
// into it.
class JsonFile {
public:
  // Throws ConfigError(file, "(JSON)", "invalid JSON at line L, column C: ...").
  JsonFile(std::string_view text, std::string file);
  // The same with relative paths (JsonValue::path()) read from `folder`
  // rather than the file's own.
  JsonFile(std::string_view text, std::string file, const std::filesystem::path &folder);
  JsonFile(const JsonFile &) = delete;
  JsonFile &operator=(const JsonFile &) = delete;

  [[nodiscard]] const std::string &name() const { return name_; }
  [[nodiscard]] JsonValue root() const { return {this, &json_, ""}; }

private:
  friend class JsonValue;
  std::string name_;
  std::filesystem::path folder_; // absolute, for JsonValue::path()
  Json json_;
};

} // namespace camhead::base
