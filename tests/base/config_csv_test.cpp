// The strict CSV reader: lines are counted as an editor counts them, blank
// and comment lines included, and every problem reads
// "FILE:LINE: FIELD: REASON" in the words of the JSON reader.
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "camhead/base/config_csv.h"

#include <gtest/gtest.h>

namespace camhead::base {
namespace {

const char *kFile = "marks.csv";
const std::vector<std::string_view> kKnown = {"t", "a", "b"};

// The message of the first problem reading `text` (header, then every row
// through `row`) finds.
std::string error_of(const std::string &text,
                     const std::function<void(CsvReader &, const CsvRow &)> &row = {},
                     CsvReader::Comments comments = CsvReader::Comments::line_start) {
  try {
    CsvReader r(kFile, text, comments);
    r.read_header(kKnown, "t,a,b");
    while (const auto cells = r.next_row())
      if (row)
        row(r, *cells);
  } catch (const ConfigError &e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ConfigCsv, LinesCountBlankAndCommentLines) {
  const std::string text = "# note\n\n  b , t\r\n1,2\n# between\n\n3,4\n5,6";
  CsvReader r(kFile, text);
  r.read_header(kKnown, "t,a,b");
  EXPECT_EQ(r.line(), 3);
  EXPECT_EQ(r.columns(), (std::vector<std::size_t>{2, 0}));
  EXPECT_TRUE(r.has_column("t"));
  EXPECT_FALSE(r.has_column("a"));
  std::vector<int> lines;
  std::vector<std::string> b;
  while (const auto row = r.next_row()) {
    lines.push_back(r.line());
    b.emplace_back(r.cell(*row, "b"));
    EXPECT_EQ(r.cell(*row, "a"), ""); // not in the header
  }
  EXPECT_EQ(lines, (std::vector<int>{4, 7, 8}));
  EXPECT_EQ(b, (std::vector<std::string>{"1", "3", "5"}));
}

TEST(ConfigCsv, RawLinesForAFormatLine) {
  CsvReader r(kFile, "# format v1\n\nt\n");
  EXPECT_EQ(r.next_line(), "# format v1");
  EXPECT_EQ(r.line(), 1);
  r.read_header(kKnown, "t");
  EXPECT_EQ(r.line(), 3);
  EXPECT_FALSE(r.next_row());
  EXPECT_FALSE(r.next_line());
  CsvReader empty(kFile, "");
  EXPECT_FALSE(empty.next_line());
  EXPECT_EQ(empty.line(), 0);
  CsvReader blank(kFile, "\n");
  EXPECT_EQ(blank.next_line(), ""); // one line, empty
  EXPECT_FALSE(blank.next_line());
}

TEST(ConfigCsv, CommentsAtLineStartOrAnywhere) {
  const std::string text = "t,a # the columns\n1,2 # a row\n";
  EXPECT_EQ(error_of(text), "marks.csv:1: a # the columns: unknown column (known: t, a, b)");
  std::vector<std::string> a;
  EXPECT_EQ(error_of(
                text, [&](CsvReader &r, const CsvRow &row) { a.emplace_back(r.cell(row, "a")); },
                CsvReader::Comments::anywhere),
            "(no error)");
  EXPECT_EQ(a, (std::vector<std::string>{"2"}));
}

TEST(ConfigCsv, HeaderProblemsNameTheLineAndColumn) {
  EXPECT_EQ(error_of("# only comments\n\n"), "marks.csv: header: missing (expected e.g. t,a,b)");
  EXPECT_EQ(error_of(""), "marks.csv: header: missing (expected e.g. t,a,b)");
  EXPECT_EQ(error_of("\nt,,a\n"), "marks.csv:2: header: empty column name (column 2)");
  EXPECT_EQ(error_of("t,c\n"), "marks.csv:1: c: unknown column (known: t, a, b)");
  EXPECT_EQ(error_of("t,a,t\n"), "marks.csv:1: t: appears twice in the header");
  try {
    CsvReader r(kFile, "# x\na\n1\n");
    r.read_header(kKnown, "t,a");
    (void)r.next_row();
    r.require_column("a");
    r.require_column("t", "every row needs a time");
    FAIL() << "accepted";
  } catch (const ConfigError &e) {
    // On the header's line, wherever the reader is by then.
    EXPECT_EQ(e.line(), 2);
    EXPECT_EQ(e.field(), "t");
    EXPECT_STREQ(e.what(), "marks.csv:2: t: missing from the header (every row needs a time)");
  }
}

TEST(ConfigCsv, RowsHaveTheHeadersFieldCount) {
  EXPECT_EQ(error_of("t,a\n1,2\n1\n"),
            "marks.csv:3: row: expected 2 fields as in the header, found 1");
  EXPECT_EQ(error_of("t,a\n1,2,3\n"),
            "marks.csv:2: row: expected 2 fields as in the header, found 3");
  EXPECT_EQ(error_of("t,a\n,\n"), "(no error)"); // empty cells are the caller's to judge
}

TEST(ConfigCsv, FailNamesTheCurrentLine) {
  EXPECT_EQ(error_of("t\n1\n\n2\n",
                     [](CsvReader &r, const CsvRow &row) {
                       if (row[0] == "2")
                         r.fail("t", "is two");
                     }),
            "marks.csv:4: t: is two");
}

// The message of reading the single cell `cell` of column a with `check`.
std::string cell_error(const std::string &cell,
                       const std::function<void(CsvReader &, std::string_view)> &check) {
  return error_of("t,a\n0," + cell + "\n",
                  [&](CsvReader &r, const CsvRow &row) { check(r, r.cell(row, "a")); });
}

TEST(ConfigCsv, Integers) {
  constexpr auto lo = std::numeric_limits<std::int32_t>::min();
  constexpr auto hi = std::numeric_limits<std::int32_t>::max();
  const auto counts = [](CsvReader &r, std::string_view c) { (void)r.integer(c, "a", lo, hi); };
  for (const char *ok : {"0", "-17", "2147483647", "-2147483648"})
    EXPECT_EQ(cell_error(ok, counts), "(no error)") << ok;
  const std::string reason = "marks.csv:2: a: must be an integer within -2147483648 .. 2147483647";
  for (const std::string &bad :
       {std::string("12.5"), std::string("8.0"), std::string("wide"), std::string(""),
        std::string("+5"), std::string("2147483648"), std::string("99999999999"),
        std::string(400, '9'), std::string("1e3"), std::string("0x10")})
    EXPECT_EQ(cell_error(bad, counts), reason) << bad.substr(0, 20);
  CsvReader r(kFile, "t\n-42\n");
  r.read_header(kKnown, "t");
  const auto row = r.next_row();
  EXPECT_EQ(r.integer((*row)[0], "t", -100, 100), -42);
}

TEST(ConfigCsv, Numbers) {
  const auto in = [](Range range, bool inf = false) {
    return [range, inf](CsvReader &r, std::string_view c) { (void)r.number(c, "a", range, inf); };
  };
  EXPECT_EQ(cell_error("2.8", in(Range::within(0.5, 128))), "(no error)");
  EXPECT_EQ(cell_error("200", in(Range::within(0.5, 128))),
            "marks.csv:2: a: must be within 0.5 .. 128");
  EXPECT_EQ(cell_error("-1", in(Range::above(0, 1e5), true)),
            "marks.csv:2: a: must be > 0 and <= 100000");
  EXPECT_EQ(cell_error("0", in(Range::above(0))), "marks.csv:2: a: must be > 0");
  for (const char *bad : {"abc", "", "nan", "inf", "-inf", "1e999", "2m"})
    EXPECT_NE(cell_error(bad, in(Range::above(0))).find("marks.csv:2: a: must be a finite number"),
              std::string::npos)
        << bad;
  // Infinity where a distance may be infinite; -inf is below the range.
  for (const char *word : {"inf", "INF", "infinity", "Infinity"})
    EXPECT_EQ(cell_error(word, in(Range::above(0, 1e5), true)), "(no error)") << word;
  EXPECT_EQ(cell_error("-inf", in(Range::above(0), true)), "marks.csv:2: a: must be > 0");
  EXPECT_EQ(cell_error("abc", in(Range::above(0), true)),
            "marks.csv:2: a: must be a number or inf");
  EXPECT_EQ(cell_error("nan", in(Range::above(0), true)),
            "marks.csv:2: a: must be a number or inf");

  CsvReader r(kFile, "t\ninf\n0.1\n");
  r.read_header(kKnown, "t");
  EXPECT_TRUE(std::isinf(r.number((*r.next_row())[0], "t", Range::above(0), true)));
  EXPECT_EQ(r.number((*r.next_row())[0], "t", Range::above(0)), 0.1);
}

} // namespace
} // namespace camhead::base
