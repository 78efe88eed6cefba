#include "camhead/base/path_text.h"

#include <cstdio>

namespace camhead::base {

namespace {

bool is_control(unsigned char c) {
  return c < 0x20 || c == 0x7f;
}

std::string escaped(unsigned char c) {
  char code[8];
  std::snprintf(code, sizeof code, "\\u%04x", c);
  return code;
}

} // namespace

std::string printable_text(std::string_view text) {
  std::string out;
  for (const char c : text)
    out += is_control(static_cast<unsigned char>(c)) ? escaped(static_cast<unsigned char>(c))
                                                     : std::string(1, c);
  return out;
}

std::string path_text_problem(std::string_view text) {
  if (text.empty())
    return "is empty";
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (!is_control(c))
      continue;
    return std::string("holds ") + (c == 0 ? "a NUL character" : "a control character") + " (" +
           escaped(c) + ") at position " + std::to_string(i) + "; a file name cannot";
  }
  return {};
}

} // namespace camhead::base
