// The strict CSV reader; see config_csv.h.
#include "camhead/base/config_csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include "config_words.h"

namespace camhead::base {
namespace {

std::string_view trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!s.empty() && space(s.front()))
    s.remove_prefix(1);
  while (!s.empty() && space(s.back()))
    s.remove_suffix(1);
  return s;
}

CsvRow split(std::string_view line) {
  CsvRow cells;
  for (std::size_t start = 0;;) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos)
      return cells;
    start = comma + 1;
  }
}

bool is_infinity_word(std::string_view s) {
  std::string lower(s);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](char c) { return c >= 'A' && c <= 'Z' ? char(c - 'A' + 'a') : c; });
  return lower == "inf" || lower == "infinity";
}

} // namespace

CsvReader::CsvReader(std::string file, std::string_view text, Comments comments)
    : file_(std::move(file)), text_(text), comments_(comments) {}

std::optional<std::string_view> CsvReader::next_line() {
  // A '\n' ends a line; after the last one there is no further, empty line.
  if (pos_ >= text_.size())
    return std::nullopt;
  const std::size_t nl = std::min(text_.find('\n', pos_), text_.size());
  const std::string_view line = text_.substr(pos_, nl - pos_);
  pos_ = nl + 1;
  ++line_;
  return trim(line);
}

std::optional<CsvRow> CsvReader::next_data() {
  while (const std::optional<std::string_view> raw = next_line()) {
    std::string_view line = *raw;
    if (comments_ == Comments::anywhere)
      line = trim(line.substr(0, line.find('#')));
    if (line.empty() || line.front() == '#')
      continue;
    return split(line);
  }
  return std::nullopt;
}

void CsvReader::read_header(const std::vector<std::string_view> &known, std::string_view example) {
  const std::optional<CsvRow> cells = next_data();
  if (!cells)
    throw ConfigError(file_, 0, "header", "missing (expected e.g. " + std::string(example) + ")");
  header_line_ = line_;
  std::string known_list;
  for (const std::string_view k : known)
    known_list += (known_list.empty() ? "" : ", ") + std::string(k);
  for (std::size_t i = 0; i < cells->size(); ++i) {
    const std::string_view name = (*cells)[i];
    if (name.empty())
      fail("header", "empty column name (column " + std::to_string(i + 1) + ")");
    const auto it = std::find(known.begin(), known.end(), name);
    if (it == known.end())
      fail(name, "unknown column (known: " + known_list + ")");
    if (has_column(name))
      fail(name, "appears twice in the header");
    header_.push_back(name);
    columns_.push_back(std::size_t(it - known.begin()));
  }
}

void CsvReader::require_column(std::string_view name, std::string_view why) const {
  if (!has_column(name))
    throw ConfigError(file_, header_line_, std::string(name),
                      "missing from the header" +
                          (why.empty() ? std::string() : " (" + std::string(why) + ")"));
}

bool CsvReader::has_column(std::string_view name) const {
  return std::find(header_.begin(), header_.end(), name) != header_.end();
}

std::optional<CsvRow> CsvReader::next_row() {
  std::optional<CsvRow> row = next_data();
  if (row && row->size() != header_.size())
    fail("row", "expected " + std::to_string(header_.size()) + " fields as in the header, found " +
                    std::to_string(row->size()));
  return row;
}

std::string_view CsvReader::cell(const CsvRow &row, std::string_view name) const {
  const auto it = std::find(header_.begin(), header_.end(), name);
  return it == header_.end() ? std::string_view{} : row[std::size_t(it - header_.begin())];
}

void CsvReader::fail(std::string_view field, const std::string &reason) const {
  throw ConfigError(file_, line_, std::string(field), reason);
}

std::int64_t CsvReader::integer(std::string_view cell, std::string_view field, std::int64_t lo,
                                std::int64_t hi) const {
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (cell.empty() || ec != std::errc{} || end != cell.data() + cell.size() || v < lo || v > hi)
    fail(field, detail::integer_reason(lo, hi));
  return v;
}

double CsvReader::number(std::string_view cell, std::string_view field, const Range &range,
                         bool infinity_allowed) const {
  if (infinity_allowed && is_infinity_word(cell))
    return std::numeric_limits<double>::infinity();
  double v = 0.0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (ec != std::errc{} || end != cell.data() + cell.size() || std::isnan(v))
    fail(field, infinity_allowed ? "must be a number or inf" : "must be a finite number");
  if (std::isinf(v) && !infinity_allowed)
    fail(field, "must be a finite number");
  if (std::isinf(v) && v > 0)
    return v;
  // -inf where inf is allowed is a number on the wrong side of the range.
  if (!range.contains(v) || std::isinf(v))
    fail(field,
         range.describe().empty() ? "must be a finite number" : "must be " + range.describe());
  return v;
}

} // namespace camhead::base
