// The strict CSV reader under the lens-trace and calibration-measurement
// readers: a header row of known column names, then rows of as many cells,
// no quoting. Every problem is a ConfigError("FILE:LINE: FIELD: REASON")
// whose field is the column, or "header" / "row" for the line as a whole;
// numbers are checked in the words of the JSON reader (config_json.h).
//
// Lines end at '\n'; spaces, tabs and a '\r' around each cell are ignored.
// Blank lines are skipped, and so are comments: lines that start with '#',
// or, with Comments::anywhere, everything from a '#' on.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "camhead/base/config_error.h"
#include "camhead/base/config_range.h"

namespace camhead::base {

using CsvRow = std::vector<std::string_view>;

class CsvReader {
public:
  enum class Comments { line_start, anywhere };

  // `text` must outlive the reader: cells are views into it.
  CsvReader(std::string file, std::string_view text, Comments comments = Comments::line_start);

  [[nodiscard]] const std::string &file() const { return file_; }
  // The number of the line read last, from 1; 0 before the first.
  [[nodiscard]] int line() const { return line_; }

  // The next line as it is, trimmed, whether blank, comment or data: for a
  // format line that must come first. nullopt at the end of the text.
  [[nodiscard]] std::optional<std::string_view> next_line();

  // The next line with data, as the header: every name one of `known`, none
  // twice, none empty. Fails on the field "header", "missing (expected e.g.
  // EXAMPLE)", when the text has no more data lines.
  void read_header(const std::vector<std::string_view> &known, std::string_view example);
  // Fails "missing from the header (WHY)" on the header's line unless the
  // header has `name`.
  void require_column(std::string_view name, std::string_view why = {}) const;
  [[nodiscard]] bool has_column(std::string_view name) const;
  // For each header position, the index of its name in `known`.
  [[nodiscard]] const std::vector<std::size_t> &columns() const { return columns_; }

  // The next data line after the header, split into as many cells as the
  // header has ("row: expected N fields as in the header, found M").
  // nullopt at the end of the text.
  [[nodiscard]] std::optional<CsvRow> next_row();
  // The cell of column `name` in `row`; empty when the header lacks it.
  [[nodiscard]] std::string_view cell(const CsvRow &row, std::string_view name) const;

  // Throws ConfigError on `field` at the line read last.
  [[noreturn]] void fail(std::string_view field, const std::string &reason) const;

  // Cell checks, failing on the line read last. An integer in [lo, hi],
  // as from_chars reads one: "must be an integer within LO .. HI".
  [[nodiscard]] std::int64_t integer(std::string_view cell, std::string_view field, std::int64_t lo,
                                     std::int64_t hi) const;
  // A finite number in `range`: "must be a finite number", then "must be " +
  // range.describe(). With infinity_allowed, "inf" and "infinity" (any case)
  // also give +infinity, beyond every upper bound ("must be a number or inf").
  [[nodiscard]] double number(std::string_view cell, std::string_view field, const Range &range,
                              bool infinity_allowed = false) const;

private:
  // The next line that is not blank or a comment, split into cells.
  [[nodiscard]] std::optional<CsvRow> next_data();

  std::string file_;
  std::string_view text_;
  Comments comments_;
  std::size_t pos_ = 0;
  int line_ = 0;
  int header_line_ = 0;
  std::vector<std::string_view> header_;
  std::vector<std::size_t> columns_;
};

} // namespace camhead::base
