// A numbered file path in printf style, "out/%05d.png", parsed once and then
// formatted by hand, so that a path given by a user never reaches printf as
// a format string. Accepted: exactly one %d (or %i, %u) with an optional 0
// flag and a width of up to 2 digits; "%%" is a literal percent sign.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace camhead::hal::video_file {

class FramePattern {
public:
  // Empty, with `error` saying why, unless `pattern` has exactly one
  // %d-style conversion.
  [[nodiscard]] static std::optional<FramePattern> parse(std::string_view pattern,
                                                         std::string &error);

  // Whether `text` is meant as a pattern at all: it holds a '%'.
  [[nodiscard]] static bool is_pattern(std::string_view text);

  // The path of frame `number`: "out/00012.png" for 12 and "out/%05d.png".
  [[nodiscard]] std::filesystem::path path(std::uint64_t number) const;

  // The pattern as given, for messages.
  [[nodiscard]] const std::string &text() const { return text_; }

private:
  FramePattern() = default;

  std::string text_;
  std::string prefix_;
  std::string suffix_;
  int width_ = 0;
  bool zero_pad_ = false;
};

} // namespace camhead::hal::video_file
