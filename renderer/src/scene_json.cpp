// The strict JSON layer under the scene reader; see scene_json.h.
#include "scene_json.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "camhead/renderer/scene_loader.h"

namespace camhead::renderer::detail {

std::string child(const std::string &field, std::string_view key) {
  return field.empty() ? std::string(key) : field + "." + std::string(key);
}

std::string show(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

bool fits_float(double v) {
  return std::abs(v) <= double(std::numeric_limits<float>::max());
}

bool is_finite_number(const Json &v) {
  return v.is_number() && std::isfinite(v.get<double>()) &&
         std::abs(v.get<double>()) != std::numeric_limits<double>::max(); // see kNonFinite
}

void Checker::fail(const std::string &field, const std::string &reason) const {
  throw SceneError(file_, field, reason);
}

void Checker::keys(const Json &d, const std::string &field, Keys required, Keys optional) const {
  if (!d.is_object())
    fail(field, "must be an object");
  for (const std::string_view k : required)
    if (!d.contains(k))
      fail(child(field, k), "missing");
  const auto listed = [](Keys ks, const std::string &k) {
    return std::find(ks.begin(), ks.end(), k) != ks.end();
  };
  for (const auto &[k, v] : d.items())
    if (!listed(required, k) && !listed(optional, k))
      fail(child(field, k), "unknown field");
}

double Checker::number(const Json &d, std::string_view k, const std::string &field, Range r,
                       std::optional<double> def) const {
  const std::string f = child(field, k);
  if (!d.contains(k))
    return def ? *def : (fail(f, "missing"), 0.0);
  const Json &v = d.at(k);
  if (!is_finite_number(v))
    fail(f, "must be a finite number");
  check_range(f, v.get<double>(), r);
  return v.get<double>();
}

std::int64_t Checker::integer(const Json &d, std::string_view k, const std::string &field,
                              std::int64_t lo, std::int64_t hi,
                              std::optional<std::int64_t> def) const {
  const std::string f = child(field, k);
  if (!d.contains(k))
    return def ? *def : (fail(f, "missing"), 0);
  const Json &v = d.at(k);
  if (!v.is_number_integer())
    fail(f, "must be an integer");
  if (v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(hi))
    fail(f, "must be <= " + std::to_string(hi));
  const std::int64_t i = v.get<std::int64_t>();
  if (i < lo)
    fail(f, "must be >= " + std::to_string(lo));
  if (i > hi)
    fail(f, "must be <= " + std::to_string(hi));
  return i;
}

Vec Checker::vec(const Json &d, std::string_view k, const std::string &field, std::size_t n,
                 Range r, std::optional<Vec> def, bool nonzero) const {
  const std::string f = child(field, k);
  if (!d.contains(k))
    return def ? *def : (fail(f, "missing"), Vec());
  const Json &v = d.at(k);
  if (!v.is_array() || v.size() != n || !std::all_of(v.begin(), v.end(), is_finite_number))
    fail(f, "must be an array of " + std::to_string(n) + " finite numbers");
  Vec out;
  for (const Json &x : v)
    out.push_back(x.get<double>());
  const auto [mn, mx] = std::minmax_element(out.begin(), out.end());
  if ((r.lo && *mn < *r.lo) || (r.hi && *mx > *r.hi))
    fail(f, "components must lie in [" + (r.lo ? show(*r.lo) : "-inf") + ", " +
                (r.hi ? show(*r.hi) : "inf") + "]");
  if (nonzero && std::all_of(out.begin(), out.end(), [](double x) { return x == 0.0; }))
    fail(f, "must not be zero");
  if (!std::all_of(out.begin(), out.end(), fits_float))
    fail(f, "components exceed the float range");
  return out;
}

std::string Checker::string(const Json &d, std::string_view k, const std::string &field,
                            std::vector<std::string> choices,
                            std::optional<std::string> def) const {
  const std::string f = child(field, k);
  if (!d.contains(k))
    return def ? *def : (fail(f, "missing"), std::string());
  const Json &v = d.at(k);
  if (!v.is_string() || v.get_ref<const std::string &>().empty())
    fail(f, "must be a non-empty string");
  const std::string &s = v.get_ref<const std::string &>();
  if (!choices.empty() && std::find(choices.begin(), choices.end(), s) == choices.end()) {
    std::string list;
    for (const std::string &c : choices)
      list += (list.empty() ? "" : ", ") + c;
    fail(f, "must be one of " + list);
  }
  return s;
}

void Checker::check_range(const std::string &f, double v, const Range &r) const {
  if (r.lo && (r.lo_open ? v <= *r.lo : v < *r.lo))
    fail(f, std::string("must be ") + (r.lo_open ? "> " : ">= ") + show(*r.lo));
  if (r.hi && v > *r.hi)
    fail(f, "must be <= " + show(*r.hi));
  if (!fits_float(v))
    fail(f, "exceeds the float range");
}

namespace {

// Python's json reads NaN, Infinity, -Infinity and overflowing literals
// (1e999) as floats, and the reference then rejects them as "must be a finite
// number" on their field. nlohmann/json rejects all of them as syntax, so they
// are rewritten to a sentinel, the largest double, which is_finite_number()
// refuses. (Columns of later syntax errors on such a line shift a little.)
constexpr std::string_view kNonFinite = "1.7976931348623157e308";

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
    } else if (text.substr(i, 3) == "NaN" && (i == 0 || text[i - 1] != '-')) {
      out += kNonFinite;
      i += 2;
    } else if (text.substr(i, 8) == "Infinity") {
      out += kNonFinite;
      i += 7;
    } else if (c == '-' || std::isdigit((unsigned char)c)) {
      const std::size_t end = text.find_first_not_of("0123456789+-.eE", i);
      const std::string token(text.substr(i, end - i));
      char *stop = nullptr;
      const bool overflows =
          std::isinf(std::strtod(token.c_str(), &stop)) && stop == token.c_str() + token.size();
      out += overflows ? (c == '-' ? "-" : "") + std::string(kNonFinite) : token;
      i += token.size() - 1;
    } else {
      in_string = c == '"';
      out += c;
    }
  }
  return out;
}

} // namespace

Json parse_json(std::string_view text, const std::string &file) {
  // Python's json refuses a byte order mark; nlohmann would skip it.
  if (text.substr(0, 3) == "\xEF\xBB\xBF")
    throw SceneError(file, "", "unexpected UTF-8 byte order mark");
  try {
    return Json::parse(rewrite_non_finite(text));
  } catch (const Json::parse_error &e) {
    std::string msg = e.what();
    const std::size_t tag = msg.find("] ");
    throw SceneError(file, "", tag == std::string::npos ? msg : msg.substr(tag + 2));
  }
}

} // namespace camhead::renderer::detail
