// The lens-trace writer. See lens_trace.h for the format.
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include "camhead/hal/lens/trace/lens_trace.h"

namespace camhead::hal::lens {
namespace {

// Shortest text that parses back to the same double ("inf" for infinity).
void put_double(std::string &out, const std::optional<double> &v) {
  if (!v) {
    return;
  }
  if (std::isinf(*v)) {
    out += "inf";
    return;
  }
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, *v);
  out.append(text, ec == std::errc{} ? end : text);
}

void put_int(std::string &out, const std::optional<std::int32_t> &v) {
  if (v) {
    out += std::to_string(*v);
  }
}

// Nanoseconds as decimal seconds with the trailing zeros cut, keeping one
// decimal: 10'000'000 -> "0.01", 2'000'000'000 -> "2.0".
void put_seconds(std::string &out, std::int64_t ns) {
  std::string fraction = std::to_string(ns % 1'000'000'000);
  fraction.insert(0, 9 - fraction.size(), '0');
  while (fraction.size() > 1 && fraction.back() == '0') {
    fraction.pop_back();
  }
  out += std::to_string(ns / 1'000'000'000);
  out += '.';
  out += fraction;
}

struct FileCloser {
  void operator()(std::FILE *f) const { std::fclose(f); }
};

} // namespace

std::string format_trace_header(std::string_view comment) {
  std::string out(kTraceMagic);
  out += '\n';
  while (!comment.empty()) {
    const std::size_t nl = comment.find('\n');
    out += "# ";
    out += comment.substr(0, nl);
    out += '\n';
    comment = nl == std::string_view::npos ? std::string_view{} : comment.substr(nl + 1);
  }
  out += kTraceColumns;
  out += '\n';
  return out;
}

std::string format_trace_row(const EncoderReading &r) {
  if (r.t_ns < 0) {
    throw std::invalid_argument("lens trace row: t_ns " + std::to_string(r.t_ns) +
                                " is before the trace's start");
  }
  std::string out;
  put_seconds(out, r.t_ns);
  out += ',';
  put_int(out, r.focus);
  out += ',';
  put_int(out, r.iris);
  out += ',';
  put_int(out, r.zoom);
  out += ',';
  put_double(out, r.focus_distance_m);
  out += ',';
  put_double(out, r.f_stop);
  out += ',';
  put_double(out, r.focal_length_mm);
  return out;
}

std::string format_lens_trace(std::span<const EncoderReading> readings, std::string_view comment) {
  std::string out = format_trace_header(comment);
  std::int64_t previous = 0;
  for (const EncoderReading &r : readings) {
    if (r.t_ns < previous) {
      throw std::invalid_argument("lens trace: t_ns " + std::to_string(r.t_ns) +
                                  " runs backwards from " + std::to_string(previous));
    }
    previous = r.t_ns;
    out += format_trace_row(r);
    out += '\n';
  }
  return out;
}

void write_lens_trace(const std::filesystem::path &path, std::span<const EncoderReading> readings,
                      std::string_view comment) {
  const std::string text = format_lens_trace(readings, comment);
  const std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "wb"));
  if (!file) {
    throw TraceError(path.string(), 0, "", std::string("cannot create: ") + std::strerror(errno));
  }
  if (std::fwrite(text.data(), 1, text.size(), file.get()) != text.size() ||
      std::fflush(file.get()) != 0) {
    throw TraceError(path.string(), 0, "", std::string("cannot write: ") + std::strerror(errno));
  }
}

} // namespace camhead::hal::lens
