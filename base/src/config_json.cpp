// The strict JSON reader; see config_json.h.
#include "camhead/base/config_json.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <unordered_set>

#include "camhead/base/path_text.h"
#include "config_words.h"

namespace camhead::base {
namespace {

// An empty key is named as JSON spells it: a field is never blank.
std::string child(const std::string &field, std::string_view key) {
  const std::string name = key.empty() ? std::string("\"\"") : std::string(key);
  return field.empty() ? name : field + "." + name;
}

// Python's json reads NaN, Infinity, -Infinity and overflowing literals
// (1e999, a 400-digit integer) as floats, for the readers to refuse on their
// field. nlohmann/json refuses them while parsing, as a syntax error or as
// out_of_range.406, before any field is known; so they are rewritten to a
// sentinel, the largest double, which finite_number() refuses. (Columns of
// later syntax errors on such a line shift a little.)
constexpr std::string_view kNonFinite = "1.7976931348623157e308";

bool finite_number(const Json &v) {
  if (!v.is_number())
    return false;
  const double x = v.get<double>();
  return std::isfinite(x) && std::abs(x) != std::numeric_limits<double>::max();
}

// A number-like token: each literal strtod reads in it that overflows becomes
// the sentinel, the rest stays for nlohmann to judge.
void rewrite_number(const std::string &token, std::string &out) {
  const char *p = token.c_str();
  const char *const end = p + token.size();
  while (p < end) {
    char *stop = nullptr;
    const double v = std::strtod(p, &stop);
    if (stop == p) {
      out += *p++;
      continue;
    }
    if (std::isinf(v)) {
      if (*p == '-' || *p == '+')
        out += *p;
      out += kNonFinite;
    } else {
      out.append(p, static_cast<std::size_t>(stop - p));
    }
    p = stop;
  }
}

bool word_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '.' || c == '+' ||
         c == '-';
}

std::string rewrite_non_finite(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      out += c;
      if (c == '\\' && i + 1 < text.size())
        out += text[++i];
      else if (c == '"')
        in_string = false;
    } else if ((text.substr(i, 3) == "NaN" && (i == 0 || text[i - 1] != '-')) ||
               text.substr(i, 8) == "Infinity") {
      // The whole word goes: "NaN4" is no more a finite number than "NaN",
      // and the sentinel followed by "4" would overflow.
      std::size_t end = i;
      while (end < text.size() && word_char(text[end]))
        ++end;
      out += kNonFinite;
      i = end - 1;
    } else if (c == '-' || std::isdigit(static_cast<unsigned char>(c)) != 0) {
      const std::size_t end = std::min(text.find_first_not_of("0123456789+-.eE", i), text.size());
      rewrite_number(std::string(text.substr(i, end - i)), out);
      i = end - 1;
    } else {
      in_string = c == '"';
      out += c;
    }
  }
  return out;
}

// nlohmann's "[json.exception.parse_error.101] parse error at line 3, column
// 13: syntax error ..." as "invalid JSON at line 3, column 13: syntax error ...".
std::string syntax_reason(const std::string &what) {
  constexpr std::string_view kParseError = "] parse error";
  const std::size_t tag = what.find(kParseError);
  if (tag != std::string::npos)
    return "invalid JSON" + what.substr(tag + kParseError.size());
  const std::size_t bracket = what.find("] ");
  return "invalid JSON: " + (bracket == std::string::npos ? what : what.substr(bracket + 2));
}

// Refuses a key given twice in one object, naming its field: a parsed
// object keeps only one of them, so the other would be ignored without a
// word (a second "camera" silently replacing the first). Follows the
// parser's events to know each key's field path.
class DuplicateKeyCheck {
public:
  explicit DuplicateKeyCheck(const std::string &file) : file_(file) {}

  bool operator()(int, nlohmann::detail::parse_event_t event, const Json &parsed) {
    using Event = nlohmann::detail::parse_event_t;
    switch (event) {
    case Event::object_start:
    case Event::array_start:
      stack_.push_back({event == Event::array_start, 0, {}, {}});
      break;
    case Event::key: {
      Level &level = stack_.back();
      const std::string key = parsed.get<std::string>();
      if (!level.keys.insert(key).second)
        throw ConfigError(file_, child(field(stack_.size() - 1), key),
                          "given twice in one object; only one would count: give it once");
      level.key = key;
      break;
    }
    case Event::object_end:
    case Event::array_end:
      stack_.pop_back();
      next_element();
      break;
    case Event::value:
      next_element();
      break;
    }
    return true;
  }

private:
  struct Level {
    bool array;
    std::size_t index;
    std::string key;                      // an object's current member
    std::unordered_set<std::string> keys; // an object's members so far
  };

  void next_element() {
    if (!stack_.empty() && stack_.back().array)
      ++stack_.back().index;
  }

  // The field of the value being read at depth `depth` (its parents' keys
  // and indices), as JsonValue names fields.
  [[nodiscard]] std::string field(std::size_t depth) const {
    std::string out;
    for (std::size_t i = 0; i < depth; ++i)
      out = stack_[i].array ? out + "[" + std::to_string(stack_[i].index) + "]"
                            : child(out, stack_[i].key);
    return out;
  }

  const std::string &file_;
  std::vector<Level> stack_;
};

} // namespace

namespace {
std::filesystem::path folder_of(const std::string &file) {
  std::error_code ec;
  const std::filesystem::path abs = std::filesystem::absolute(file, ec);
  return (ec ? std::filesystem::path(file) : abs).parent_path();
}
} // namespace

JsonFile::JsonFile(std::string_view text, std::string file)
    : JsonFile(text, file, folder_of(file)) {}

JsonFile::JsonFile(std::string_view text, std::string file, const std::filesystem::path &folder)
    : name_(std::move(file)) {
  std::error_code ec;
  const std::filesystem::path abs = std::filesystem::absolute(folder, ec);
  folder_ = ec || folder.empty() ? folder : abs;
  try {
    json_ = Json::parse(rewrite_non_finite(text), DuplicateKeyCheck(name_));
  } catch (const Json::exception &e) {
    // parse_error, and out_of_range.406 should a literal escape the rewrite.
    throw ConfigError(name_, "(JSON)", syntax_reason(e.what()));
  }
}

const std::string &JsonValue::file() const {
  return file_->name_;
}

void JsonValue::fail(const std::string &reason) const {
  throw ConfigError(file(), field_.empty() ? "(top level)" : field_, reason);
}

void JsonValue::fail_member(std::string_view key, const std::string &reason) const {
  throw ConfigError(file(), child(field_, key), reason);
}

bool JsonValue::has(std::string_view key) const {
  return value_->is_object() && value_->contains(key);
}

JsonValue JsonValue::at(std::string_view key, std::string_view hint) const {
  if (!has(key))
    throw ConfigError(file(), child(field_, key),
                      hint.empty() ? "missing" : "missing (" + std::string(hint) + ")");
  return {file_, &value_->find(key).value(), child(field_, key)};
}

std::optional<JsonValue> JsonValue::find(std::string_view key) const {
  if (!has(key))
    return std::nullopt;
  return at(key);
}

std::vector<std::pair<std::string, JsonValue>> JsonValue::members() const {
  if (!value_->is_object())
    fail("must be an object");
  std::vector<std::pair<std::string, JsonValue>> out;
  for (const auto &[k, v] : value_->items())
    out.emplace_back(k, JsonValue(file_, &v, child(field_, k)));
  return out;
}

std::vector<JsonValue> JsonValue::elements(std::string_view what) const {
  if (!value_->is_array())
    fail(what.empty() ? "must be an array" : "must be an array of " + std::string(what));
  std::vector<JsonValue> out;
  for (std::size_t i = 0; i < value_->size(); ++i)
    out.push_back({file_, &(*value_)[i], field_ + "[" + std::to_string(i) + "]"});
  return out;
}

const JsonValue &JsonValue::object(const Keys &required, const Keys &optional) const {
  if (!value_->is_object())
    fail("must be an object");
  for (const std::string_view k : required)
    if (!value_->contains(k))
      throw ConfigError(file(), child(field_, k), "missing");
  const auto listed = [](const Keys &ks, const std::string &k) {
    return std::find(ks.begin(), ks.end(), k) != ks.end();
  };
  for (const auto &[k, v] : value_->items())
    if (!listed(required, k) && !listed(optional, k))
      throw ConfigError(file(), child(field_, k), "unknown field");
  return *this;
}

std::string JsonValue::string() const {
  if (!value_->is_string() || value_->get_ref<const std::string &>().empty())
    fail("must be a non-empty string");
  return value_->get<std::string>();
}

std::string JsonValue::string(const Keys &choices) const {
  const std::string s = string();
  if (std::find(choices.begin(), choices.end(), s) == choices.end()) {
    std::string list;
    for (const std::string_view c : choices)
      list += (list.empty() ? "" : ", ") + std::string(c);
    fail("must be one of " + list);
  }
  return s;
}

std::string JsonValue::text() const {
  if (!value_->is_string())
    fail("must be a string");
  return value_->get<std::string>();
}

bool JsonValue::boolean() const {
  if (!value_->is_boolean())
    fail("must be true or false");
  return value_->get<bool>();
}

double JsonValue::number(const Range &range) const {
  if (!finite_number(*value_))
    fail("must be a finite number");
  const double x = value_->get<double>();
  if (!range.contains(x))
    fail("must be " + range.describe());
  return x;
}

std::int64_t JsonValue::integer(std::int64_t lo, std::int64_t hi) const {
  // nlohmann keeps non-negative integers unsigned, so a value beyond int64
  // must be compared as one; anything written with a point or an exponent,
  // or too long for 64 bits, is a float and fails alike.
  const Json &v = *value_;
  bool ok = false;
  if (v.is_number_unsigned()) {
    const std::uint64_t u = v.get<std::uint64_t>();
    ok = hi >= 0 && u <= std::uint64_t(hi) && (lo <= 0 || u >= std::uint64_t(lo));
  } else if (v.is_number_integer()) {
    const std::int64_t i = v.get<std::int64_t>();
    ok = i >= lo && i <= hi;
  }
  if (!ok)
    fail(detail::integer_reason(lo, hi));
  return v.get<std::int64_t>();
}

std::vector<double> JsonValue::numbers(std::size_t n, const Range &range) const {
  const Json &v = *value_;
  if (!v.is_array() || v.size() != n || !std::all_of(v.begin(), v.end(), finite_number))
    fail("must be an array of " + std::to_string(n) + " finite numbers");
  std::vector<double> out;
  for (const Json &x : v)
    out.push_back(x.get<double>());
  if (!std::all_of(out.begin(), out.end(), [&](double x) { return range.contains(x); }))
    fail("components must be " + range.describe());
  return out;
}

std::filesystem::path JsonValue::path() const {
  const std::string name = string();
  if (const std::string problem = path_text_problem(name); !problem.empty())
    fail(problem);
  // An absolute path replaces the folder.
  return (file_->folder_ / name).lexically_normal();
}

} // namespace camhead::base
