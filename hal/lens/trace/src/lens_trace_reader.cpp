// The strict lens-trace reader. See lens_trace.h and README.md for the format.
// Lines, header and numbers are base's strict CSV reader (config_csv.h); the
// format line and the exact decimal seconds are the trace's own.
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "camhead/base/config_csv.h"
#include "camhead/hal/lens/trace/lens_trace.h"

namespace camhead::hal::lens {
namespace {

using base::CsvReader;
using base::CsvRow;
using base::Range;

// In the order of kNames, whose index columns() gives.
enum class Column { t_s, focus, iris, zoom, focus_m, f_stop, focal_mm };
const std::vector<std::string_view> kNames = {"t_s",     "focus",  "iris",    "zoom",
                                              "focus_m", "f_stop", "focal_mm"};

constexpr std::string_view kVersionPrefix = "# camhead lens trace v";
// Nine integer digits of seconds: 31 years of trace, far inside int64 ns.
constexpr std::size_t kMaxSecondDigits = 9;

bool all_digits(std::string_view s) {
  for (const char c : s) {
    if (c < '0' || c > '9') {
      return false;
    }
  }
  return true;
}

class Reader {
public:
  Reader(const std::string &source, std::string_view text) : csv_(source, text) {}

  LensTrace read() {
    LensTrace out{csv_.file(), {}};
    const std::optional<std::string_view> first = csv_.next_line();
    if (!first) {
      throw TraceError(csv_.file(), 0, "(file)",
                       "empty (a trace starts with \"" + std::string(kTraceMagic) + "\")");
    }
    version(*first);
    csv_.read_header(kNames, kTraceColumns);
    csv_.require_column("t_s", "every row needs a time");
    while (const std::optional<CsvRow> cells = csv_.next_row()) {
      out.readings.push_back(row(*cells));
    }
    return out;
  }

private:
  void version(std::string_view line) const {
    if (line == kTraceMagic) {
      return;
    }
    if (line.substr(0, kVersionPrefix.size()) == kVersionPrefix) {
      csv_.fail("version", "version " + std::string(line.substr(kVersionPrefix.size() - 1)) +
                               " is not supported (this reader reads v1)");
    }
    csv_.fail("format", "not a camhead lens trace: the first line must be \"" +
                            std::string(kTraceMagic) + "\"");
  }

  EncoderReading row(const CsvRow &cells) {
    EncoderReading r;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const std::string_view v = cells[i];
      const auto c = static_cast<Column>(csv_.columns()[i]);
      if (v.empty()) {
        if (c == Column::t_s) {
          csv_.fail("t_s", "empty (every row needs a time)");
        }
        continue;
      }
      const std::string_view name = kNames[csv_.columns()[i]];
      switch (c) {
      case Column::t_s:
        r.t_ns = seconds(v);
        break;
      case Column::focus:
        r.focus = counts(v, name);
        break;
      case Column::iris:
        r.iris = counts(v, name);
        break;
      case Column::zoom:
        r.zoom = counts(v, name);
        break;
      case Column::focus_m:
        r.focus_distance_m = csv_.number(v, name, Range::above(0.0), /*infinity_allowed=*/true);
        break;
      case Column::f_stop:
        r.f_stop = csv_.number(v, name, Range::above(0.0));
        break;
      case Column::focal_mm:
        r.focal_length_mm = csv_.number(v, name, Range::above(0.0));
        break;
      }
    }
    if (previous_t_ && r.t_ns < *previous_t_) {
      csv_.fail("t_s", "time runs backwards: earlier than the row on line " +
                           std::to_string(previous_line_));
    }
    previous_t_ = r.t_ns;
    previous_line_ = csv_.line();
    return r;
  }

  // Decimal seconds to nanoseconds, exactly: a double would turn 0.1 into
  // 99999999.99... ns and break the writer's round trip.
  std::int64_t seconds(std::string_view v) const {
    if (v.front() == '-') {
      csv_.fail("t_s", "negative (trace time starts at 0)");
    }
    const std::size_t dot = v.find('.');
    const std::string_view whole = v.substr(0, dot);
    const std::string_view fraction =
        dot == std::string_view::npos ? std::string_view{} : v.substr(dot + 1);
    if (whole.empty() || !all_digits(whole) || !all_digits(fraction) ||
        (dot != std::string_view::npos && fraction.empty())) {
      csv_.fail("t_s", "\"" + std::string(v) + "\" is not a decimal number of seconds (e.g. 0.01)");
    }
    if (whole.size() > kMaxSecondDigits) {
      csv_.fail("t_s",
                "too large (at most " + std::to_string(kMaxSecondDigits) + " digits of seconds)");
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

  std::int32_t counts(std::string_view v, std::string_view name) const {
    return static_cast<std::int32_t>(csv_.integer(v, name, std::numeric_limits<std::int32_t>::min(),
                                                  std::numeric_limits<std::int32_t>::max()));
  }

  CsvReader csv_;
  std::optional<std::int64_t> previous_t_;
  int previous_line_ = 0;
};

} // namespace

LensTrace parse_lens_trace(std::string_view text, const std::string &source) {
  try {
    return Reader(source, text).read();
  } catch (const base::ConfigError &e) {
    throw TraceError(e);
  }
}

LensTrace read_lens_trace(const std::filesystem::path &path) {
  std::string text;
  try {
    text = base::read_config_file(path);
  } catch (const base::ConfigError &e) {
    throw TraceError(e);
  }
  return parse_lens_trace(text, path.string());
}

} // namespace camhead::hal::lens
