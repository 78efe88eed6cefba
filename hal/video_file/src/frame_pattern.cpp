// printf-style frame numbers without printf; see frame_pattern.h.
#include "camhead/hal/video_file/frame_pattern.h"

namespace camhead::hal::video_file {

bool FramePattern::is_pattern(std::string_view text) {
  return text.find('%') != std::string_view::npos;
}

std::optional<FramePattern> FramePattern::parse(std::string_view pattern, std::string &error) {
  FramePattern out;
  out.text_ = std::string(pattern);
  int conversions = 0;
  std::string *literal = &out.prefix_;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      *literal += pattern[i];
      continue;
    }
    std::size_t j = i + 1;
    if (j < pattern.size() && pattern[j] == '%') {
      *literal += '%';
      i = j;
      continue;
    }
    const bool zero = j < pattern.size() && pattern[j] == '0';
    if (zero)
      ++j;
    int width = 0;
    std::size_t digits = 0;
    while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9' && digits < 3) {
      width = width * 10 + (pattern[j] - '0');
      ++j;
      ++digits;
    }
    if (j >= pattern.size() || digits > 2 ||
        (pattern[j] != 'd' && pattern[j] != 'i' && pattern[j] != 'u')) {
      error = "'" + std::string(pattern.substr(i, j + 1 - i)) +
              "' is not a frame number: use %d or %0Nd (and %% for a percent sign)";
      return std::nullopt;
    }
    if (++conversions > 1)
      break;
    out.zero_pad_ = zero;
    out.width_ = width;
    literal = &out.suffix_;
    i = j;
  }
  if (conversions != 1) {
    error = "needs exactly one frame number (%d or %0Nd), found " +
            std::string(conversions == 0 ? "none" : "more");
    return std::nullopt;
  }
  return out;
}

std::filesystem::path FramePattern::path(std::uint64_t number) const {
  std::string digits = std::to_string(number);
  if (digits.size() < static_cast<std::size_t>(width_))
    digits.insert(0, static_cast<std::size_t>(width_) - digits.size(), zero_pad_ ? '0' : ' ');
  return prefix_ + digits + suffix_;
}

} // namespace camhead::hal::video_file
