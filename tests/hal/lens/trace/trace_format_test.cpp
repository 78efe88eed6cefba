// Lens trace CSV: writer -> reader round trips bit for bit, and every way a
// file can be wrong is reported as FILE:LINE: FIELD: REASON.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

#include "camhead/hal/lens/trace/lens_trace.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

std::vector<EncoderReading> awkward_readings() {
  std::vector<EncoderReading> r(5);
  r[0].t_ns = 0;
  r[0].focus = 0;
  r[0].iris = -17; // quadrature counts can be negative
  r[1].t_ns = 10'000'000;
  r[1].focus = std::numeric_limits<std::int32_t>::max();
  r[1].zoom = std::numeric_limits<std::int32_t>::min();
  r[2].t_ns = 10'000'000;            // equal times are allowed
  r[2].focus_distance_m = 0.1 + 0.2; // not a short decimal
  r[2].f_stop = 2.8;
  r[2].focal_length_mm = 1.0 / 3.0;
  r[3].t_ns = 1'234'567'891; // every nanosecond digit matters
  r[3].focus_distance_m = std::numeric_limits<double>::infinity();
  r[3].f_stop = std::numeric_limits<double>::denorm_min();
  r[4].t_ns = 3'600'000'000'000; // one hour, no axes at all
  return r;
}

TEST(LensTraceFormat, WriterOutputLooksAsDocumented) {
  EncoderReading r;
  r.t_ns = 20'000'000;
  r.focus = 13600;
  r.iris = 600;
  r.f_stop = 2.0;
  EXPECT_EQ(format_trace_row(r), "0.02,13600,600,,,2,");
  EXPECT_EQ(format_lens_trace(std::vector<EncoderReading>{r}, "one\ntwo"),
            "# camhead lens trace v1\n# one\n# two\n"
            "t_s,focus,iris,zoom,focus_m,f_stop,focal_mm\n0.02,13600,600,,,2,\n");
  r.t_ns = 2'000'000'000;
  EXPECT_EQ(format_trace_row(r).substr(0, 4), "2.0,");
}

TEST(LensTraceFormat, RoundTripIsExact) {
  const std::vector<EncoderReading> original = awkward_readings();
  const LensTrace back = parse_lens_trace(format_lens_trace(original), "mem.csv");
  EXPECT_EQ(back.source, "mem.csv");
  EXPECT_EQ(back.readings, original);
}

TEST(LensTraceFormat, FileRoundTrip) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("camhead_trace_rt_" + std::to_string(::getpid()) + ".csv");
  write_lens_trace(path, awkward_readings(), "file round trip");
  const LensTrace back = read_lens_trace(path);
  std::filesystem::remove(path);
  EXPECT_EQ(back.readings, awkward_readings());
  EXPECT_EQ(back.source, path.string());
}

TEST(LensTraceFormat, ReaderTakesColumnsInAnyOrderCommentsAndCrlf) {
  const LensTrace t = parse_lens_trace("# camhead lens trace v1\r\n"
                                       "# a comment\r\n"
                                       "\r\n"
                                       " zoom , t_s ,focus_m\r\n"
                                       "5,0.5,inf\r\n"
                                       "# between rows\n"
                                       ",1,2.5\n"
                                       "7,1.0000000004,\n"
                                       "7,1.0000000005\t,",
                                       "x.csv");
  ASSERT_EQ(t.readings.size(), 4u);
  EXPECT_EQ(t.readings[0].t_ns, 500'000'000);
  EXPECT_EQ(t.readings[0].zoom, 5);
  EXPECT_FALSE(t.readings[0].focus);
  EXPECT_TRUE(std::isinf(*t.readings[0].focus_distance_m));
  EXPECT_FALSE(t.readings[1].zoom);
  EXPECT_EQ(t.readings[1].t_ns, 1'000'000'000);
  EXPECT_EQ(t.readings[1].focus_distance_m, 2.5);
  // Beyond nine decimals, seconds round to the nearest nanosecond.
  EXPECT_EQ(t.readings[2].t_ns, 1'000'000'000);
  EXPECT_EQ(t.readings[3].t_ns, 1'000'000'001);
}

TEST(LensTraceFormat, HeaderOnlyIsAnEmptyTrace) {
  const LensTrace t = parse_lens_trace("# camhead lens trace v1\nt_s,focus\n", "e.csv");
  EXPECT_TRUE(t.readings.empty());
}

struct BadTrace {
  const char *name;
  std::string_view text;
  int line;
  std::string_view field;
  std::string_view reason; // a part of the reason
};

void PrintTo(const BadTrace &b, std::ostream *os) {
  *os << b.name;
}

class LensTraceRejects : public testing::TestWithParam<BadTrace> {};

TEST_P(LensTraceRejects, NamesFileLineAndField) {
  const BadTrace &b = GetParam();
  try {
    (void)parse_lens_trace(b.text, "lenses/bad.csv");
    FAIL() << "accepted " << b.name;
  } catch (const TraceError &e) {
    EXPECT_EQ(e.file(), "lenses/bad.csv");
    EXPECT_EQ(e.line(), b.line) << e.what();
    EXPECT_EQ(e.field(), b.field) << e.what();
    EXPECT_NE(e.reason().find(b.reason), std::string::npos) << e.what();
    const std::string prefix =
        "lenses/bad.csv:" + std::to_string(b.line) + ": " + std::string(b.field) + ": ";
    EXPECT_EQ(std::string(e.what()).rfind(prefix, 0), 0u) << e.what();
  }
}

// A valid head, so that each case below reads as the file it is.
#define HEAD "# camhead lens trace v1\nt_s,focus,iris,zoom,focus_m,f_stop,focal_mm\n"

INSTANTIATE_TEST_SUITE_P(
    Cases, LensTraceRejects,
    testing::Values(
        BadTrace{"not_a_trace", "t_s,focus\n0,1\n", 1, "format", "first line must be"},
        BadTrace{"newer_version", "# camhead lens trace v2\nt_s\n0\n", 1, "version",
                 "v2 is not supported"},
        BadTrace{"unknown_column", "# camhead lens trace v1\nt_s,focus,temperature\n", 2,
                 "temperature", "unknown column"},
        BadTrace{"duplicate_column", "# camhead lens trace v1\nt_s,focus,focus\n", 2, "focus",
                 "twice"},
        BadTrace{"no_time_column", "# camhead lens trace v1\nfocus,iris\n", 2, "t_s", "missing"},
        BadTrace{"empty_column_name", "# camhead lens trace v1\nt_s,,focus\n", 2, "header",
                 "empty column name"},
        BadTrace{"time_backwards", HEAD "0.0,1,,,,,\n# c\n0.02,1,,,,,\n0.01,1,,,,,\n", 6, "t_s",
                 "backwards: earlier than the row on line 5"},
        BadTrace{"negative_time", HEAD "-0.5,1,,,,,\n", 3, "t_s", "negative"},
        BadTrace{"time_in_exponent_form", HEAD "1e-3,1,,,,,\n", 3, "t_s", "not a decimal"},
        BadTrace{"time_with_bare_dot", HEAD "1.,1,,,,,\n", 3, "t_s", "not a decimal"},
        BadTrace{"missing_time", HEAD ",1,,,,,\n", 3, "t_s", "empty"},
        BadTrace{"huge_time", HEAD "12345678901,1,,,,,\n", 3, "t_s", "too large"},
        BadTrace{"fractional_counts", HEAD "0,1.5,,,,,\n", 3, "focus", "must be an integer within"},
        BadTrace{"counts_beyond_int32", HEAD "0,,4294967296,,,,\n", 3, "iris",
                 "must be an integer within -2147483648 .. 2147483647"},
        BadTrace{"text_counts", HEAD "0,,,wide,,,\n", 3, "zoom", "must be an integer within"},
        BadTrace{"zero_distance", HEAD "0,,,,0,,\n", 3, "focus_m", "must be > 0"},
        BadTrace{"nan_f_stop", HEAD "0,,,,,nan,\n", 3, "f_stop", "must be a finite number"},
        BadTrace{"infinite_focal_length", HEAD "0,,,,,,inf\n", 3, "focal_mm",
                 "must be a finite number"},
        BadTrace{"negative_infinity", HEAD "0,,,,-inf,,\n", 3, "focus_m", "must be > 0"},
        BadTrace{"too_few_cells", HEAD "0,1,2\n", 3, "row", "expected 7 fields"},
        BadTrace{"too_many_cells", HEAD "0,1,2,3,4,5,6,7\n", 3, "row", "found 8"}),
    [](const testing::TestParamInfo<BadTrace> &p) { return std::string(p.param.name); });

#undef HEAD

TEST(LensTraceFormat, WholeFileProblemsNameTheFile) {
  try {
    (void)parse_lens_trace("", "empty.csv");
    FAIL();
  } catch (const TraceError &e) {
    EXPECT_EQ(std::string(e.what()).rfind("empty.csv: (file): empty (a trace starts with", 0), 0u)
        << e.what();
  }
  try {
    (void)parse_lens_trace("# camhead lens trace v1\n# only comments\n", "nohead.csv");
    FAIL();
  } catch (const TraceError &e) {
    EXPECT_EQ(std::string(e.what()).rfind("nohead.csv: header: missing (expected e.g. t_s,", 0), 0u)
        << e.what();
  }
  try {
    (void)read_lens_trace("/nonexistent/camhead/trace.csv");
    FAIL();
  } catch (const TraceError &e) {
    EXPECT_EQ(
        std::string(e.what()),
        "/nonexistent/camhead/trace.csv: (file): cannot be opened: No such file or directory");
  }
}

TEST(LensTraceFormat, WriterRefusesTimeBeforeStartOrBackwards) {
  std::vector<EncoderReading> r(2);
  r[0].t_ns = 5;
  r[1].t_ns = 4;
  EXPECT_THROW((void)format_lens_trace(r), std::invalid_argument);
  r[0].t_ns = -1;
  EXPECT_THROW((void)format_trace_row(r[0]), std::invalid_argument);
}

} // namespace
} // namespace camhead::hal::lens
