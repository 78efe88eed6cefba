// Recorded lens traces: a CSV file of encoder readings over time, the data of
// the replay backend (trace_replay.h) and what the recorder (trace_recorder.h)
// writes. Format in hal/lens/trace/README.md; in short:
//
//   # camhead lens trace v1
//   # any further comment lines
//   t_s,focus,iris,zoom,focus_m,f_stop,focal_mm
//   0.0,13600,600,0,,,
//   0.01,13598,601,0,,,
//
// The first line names the format and its version. The header row names the
// columns (any order, t_s required, the rest optional); an empty cell is a
// field the reading does not carry. t_s is seconds of trace time, >= 0 and
// never decreasing; counts are 32-bit integers; focus_m ("inf" allowed),
// f_stop and focal_mm are > 0.
//
// The reader is strict, like every camhead file reader: a trace is data that a
// test or a demo trusts, so a bad cell stops the load with
// "FILE:LINE: FIELD: REASON" instead of becoming a jump of the rendered focus.
//
// Thread safety: free functions on values; nothing shared.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "camhead/base/config_error.h"
#include "camhead/hal/lens/lens_encoder.h"

namespace camhead::hal::lens {

inline constexpr std::string_view kTraceMagic = "# camhead lens trace v1";
inline constexpr std::string_view kTraceColumns = "t_s,focus,iris,zoom,focus_m,f_stop,focal_mm";

// A trace file that cannot be used. what() reads "FILE:LINE: FIELD: REASON"
// for a line of it, "FILE: FIELD: REASON" for the file as a whole
// (line() == 0; FIELD "(file)" when it cannot be read), and "FILE: REASON"
// for a trace that cannot be replayed or written (base/config_error.h).
class TraceError : public base::ConfigError {
public:
  using base::ConfigError::ConfigError;
  explicit TraceError(const base::ConfigError &e) : base::ConfigError(e) {}
};

struct LensTrace {
  std::string source; // the file name as given, for messages and LensEncoder::name()
  // t_ns is trace time: t_s of the row in nanoseconds (exact for up to nine
  // decimals, further decimals round to the nearest nanosecond).
  std::vector<EncoderReading> readings;
};

// Throw TraceError naming `source` (or the path), the line and the column.
[[nodiscard]] LensTrace parse_lens_trace(std::string_view text, const std::string &source);
[[nodiscard]] LensTrace read_lens_trace(const std::filesystem::path &path);

// The writer's side. Readings are in trace time: t_ns >= 0 and never
// decreasing, else std::invalid_argument (a caller's bug, not bad data).
// Numbers are written so that the reader gets the identical double back; t_s
// is exact to the nanosecond. `comment` lines (without '#', split at '\n')
// follow the first line.
[[nodiscard]] std::string format_trace_header(std::string_view comment = {});
[[nodiscard]] std::string format_trace_row(const EncoderReading &reading);
[[nodiscard]] std::string format_lens_trace(std::span<const EncoderReading> readings,
                                            std::string_view comment = {});
// Throws TraceError naming the path when it cannot be written.
void write_lens_trace(const std::filesystem::path &path, std::span<const EncoderReading> readings,
                      std::string_view comment = {});

} // namespace camhead::hal::lens
