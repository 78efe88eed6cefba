// The strict lens-trace reader. See lens_trace.h and README.md for the format.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>

#include "camhead/hal/lens/trace/lens_trace.h"

namespace camhead::hal::lens {
namespace {

enum class Column { t_s, focus, iris, zoom, focus_m, f_stop, focal_mm };
constexpr std::array<std::string_view, 7> kNames = {"t_s",     "focus",  "iris",    "zoom",
                                                    "focus_m", "f_stop", "focal_mm"};

constexpr std::string_view kVersionPrefix = "# camhead lens trace v";
// Nine integer digits of seconds: 31 years of trace, far inside int64 ns.
constexpr std::size_t kMaxSecondDigits = 9;

std::string_view trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!s.empty() && space(s.front())) {
    s.remove_prefix(1);
  }
  while (!s.empty() && space(s.back())) {
    s.remove_suffix(1);
  }
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> cells;
  for (std::size_t start = 0;;) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) {
      return cells;
    }
    start = comma + 1;
  }
}

bool all_digits(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

class Reader {
public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  LensTrace read(std::string_view text) {
    LensTrace out{source_, {}};
    std::size_t pos = 0;
    while (pos < text.size()) {
      const std::size_t nl = std::min(text.find('\n', pos), text.size());
      const std::string_view line = trim(text.substr(pos, nl - pos));
      pos = nl + 1;
      ++line_;
      if (line_ == 1) {
        version(line);
      } else if (line.empty() || line.front() == '#') {
        continue;
      } else if (columns_.empty()) {
        header(split(line));
      } else {
        out.readings.push_back(row(split(line)));
      }
    }
    if (line_ == 0) {
      throw TraceError(source_, 0, "",
                       "empty file (a trace starts with \"" + std::string(kTraceMagic) + "\")");
    }
    if (columns_.empty()) {
      throw TraceError(source_, 0, "",
                       "no header row (expected e.g. " + std::string(kTraceColumns) + ")");
    }
    return out;
  }

private:
  [[noreturn]] void fail(std::string_view field, const std::string &reason) const {
    throw TraceError(source_, line_, std::string(field), reason);
  }

  void version(std::string_view line) const {
    if (line == kTraceMagic) {
      return;
    }
    if (line.substr(0, kVersionPrefix.size()) == kVersionPrefix) {
      fail("version", "version " + std::string(line.substr(kVersionPrefix.size() - 1)) +
                          " is not supported (this reader reads v1)");
    }
    fail("format",
         "not a camhead lens trace: the first line must be \"" + std::string(kTraceMagic) + "\"");
  }

  void header(const std::vector<std::string_view> &cells) {
    for (const std::string_view name : cells) {
      const auto it = std::find(kNames.begin(), kNames.end(), name);
      if (name.empty()) {
        fail("header", "empty column name");
      }
      if (it == kNames.end()) {
        fail(name, "unknown column (known: " + std::string(kTraceColumns) + ")");
      }
      const auto column = static_cast<Column>(it - kNames.begin());
      if (std::find(columns_.begin(), columns_.end(), column) != columns_.end()) {
        fail(name, "appears twice in the header");
      }
      columns_.push_back(column);
    }
    if (std::find(columns_.begin(), columns_.end(), Column::t_s) == columns_.end()) {
      fail("t_s", "missing from the header (every row needs a time)");
    }
  }

  EncoderReading row(const std::vector<std::string_view> &cells) {
    if (cells.size() != columns_.size()) {
      fail("row", "expected " + std::to_string(columns_.size()) +
                      " fields as in the header, found " + std::to_string(cells.size()));
    }
    EncoderReading r;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const std::string_view v = cells[i];
      const Column c = columns_[i];
      if (v.empty()) {
        if (c == Column::t_s) {
          fail("t_s", "empty (every row needs a time)");
        }
        continue;
      }
      switch (c) {
      case Column::t_s:
        r.t_ns = seconds(v);
        break;
      case Column::focus:
        r.focus = counts(v, c);
        break;
      case Column::iris:
        r.iris = counts(v, c);
        break;
      case Column::zoom:
        r.zoom = counts(v, c);
        break;
      case Column::focus_m:
        r.focus_distance_m = positive(v, c, /*infinity_allowed=*/true);
        break;
      case Column::f_stop:
        r.f_stop = positive(v, c, false);
        break;
      case Column::focal_mm:
        r.focal_length_mm = positive(v, c, false);
        break;
      }
    }
    if (previous_t_ && r.t_ns < *previous_t_) {
      fail("t_s",
           "time runs backwards: earlier than the row on line " + std::to_string(previous_line_));
    }
    previous_t_ = r.t_ns;
    previous_line_ = line_;
    return r;
  }

  // Decimal seconds to nanoseconds, exactly: a double would turn 0.1 into
  // 99999999.99... ns and break the writer's round trip.
  std::int64_t seconds(std::string_view v) const {
    if (v.front() == '-') {
      fail("t_s", "negative (trace time starts at 0)");
    }
    const std::size_t dot = v.find('.');
    const std::string_view whole = v.substr(0, dot);
    const std::string_view fraction =
        dot == std::string_view::npos ? std::string_view{} : v.substr(dot + 1);
    if (whole.empty() || !all_digits(whole) || !all_digits(fraction) ||
        (dot != std::string_view::npos && fraction.empty())) {
      fail("t_s", "\"" + std::string(v) + "\" is not a decimal number of seconds (e.g. 0.01)");
    }
    if (whole.size() > kMaxSecondDigits) {
      fail("t_s", "too large (at most " + std::to_string(kMaxSecondDigits) + " digits of seconds)");
    }
    std::int64_t ns = 0;
    for (const char c : whole) {
      ns = ns * 10 + (c - '0');
    }
    std::int64_t frac = 0;
    for (std::size_t i = 0; i < 9; ++i) {
      frac = frac * 10 + (i < fraction.size() ? fraction[i] - '0' : 0);
    }
    const bool round_up = fraction.size() > 9 && fraction[9] >= '5';
    return ns * 1'000'000'000 + frac + (round_up ? 1 : 0);
  }

  std::int32_t counts(std::string_view v, Column c) const {
    std::int64_t n = 0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), n);
    if (ec != std::errc{} || end != v.data() + v.size()) {
      fail(kNames[static_cast<std::size_t>(c)], "\"" + std::string(v) + "\" is not an integer");
    }
    if (n < std::numeric_limits<std::int32_t>::min() ||
        n > std::numeric_limits<std::int32_t>::max()) {
      fail(kNames[static_cast<std::size_t>(c)], "outside the 32-bit encoder range");
    }
    return static_cast<std::int32_t>(n);
  }

  double positive(std::string_view v, Column c, bool infinity_allowed) const {
    const std::string_view name = kNames[static_cast<std::size_t>(c)];
    double x = 0.0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
    if (ec != std::errc{} || end != v.data() + v.size() || std::isnan(x)) {
      fail(name, "\"" + std::string(v) + "\" is not a number");
    }
    if (std::isinf(x) && !(infinity_allowed && x > 0)) {
      fail(name, infinity_allowed ? "must be > 0 (inf for infinity)" : "not a finite number");
    }
    if (!(x > 0.0)) {
      fail(name, "must be > 0");
    }
    return x;
  }

  std::string source_;
  int line_ = 0;
  std::vector<Column> columns_;
  std::optional<std::int64_t> previous_t_;
  int previous_line_ = 0;
};

} // namespace

LensTrace parse_lens_trace(std::string_view text, const std::string &source) {
  return Reader(source).read(text);
}

LensTrace read_lens_trace(const std::filesystem::path &path) {
  std::ifstream in(path, std::ios::binary);
  if (!in.is_open()) {
    throw TraceError(path.string(), 0, "", "cannot open the file");
  }
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) {
    throw TraceError(path.string(), 0, "", "cannot read the file");
  }
  return parse_lens_trace(text, path.string());
}

} // namespace camhead::hal::lens
