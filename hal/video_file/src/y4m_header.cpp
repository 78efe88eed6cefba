// The Y4M header, strictly: see y4m_header.h for what is accepted and why.
#include "camhead/hal/video_file/y4m_header.h"

#include <array>
#include <charconv>
#include <climits>
#include <cmath>
#include <numeric>
#include <system_error>

namespace camhead::hal::video_file {
namespace {

constexpr std::string_view kChromaChoices =
    "only 4:2:0 (420jpeg, 420mpeg2, 420paldv, 420) and 4:2:2 (422) are supported";

// Digits only: from_chars alone would take a leading '-' for signed types and
// we want "W+4" and "W 4" refused, not read.
bool parse_uint(std::string_view text, std::uint32_t &out) {
  if (text.empty() || text.size() > 10)
    return false;
  for (const char c : text)
    if (c < '0' || c > '9')
      return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size();
}

bool parse_ratio(std::string_view text, std::uint32_t &num, std::uint32_t &den) {
  const std::size_t colon = text.find(':');
  return colon != std::string_view::npos && parse_uint(text.substr(0, colon), num) &&
         parse_uint(text.substr(colon + 1), den);
}

// A token as it can safely appear in a message: printable ASCII, shortened.
std::string printable(std::string_view token) {
  std::string out;
  for (const char c : token.substr(0, 32))
    out += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (token.size() > 32)
    out += "...";
  return out;
}

std::string_view chroma_name(Y4mChroma chroma) {
  switch (chroma) {
  case Y4mChroma::c420jpeg:
    return "420jpeg";
  case Y4mChroma::c420mpeg2:
    return "420mpeg2";
  case Y4mChroma::c420paldv:
    return "420paldv";
  case Y4mChroma::c422:
    return "422";
  }
  return "?";
}

class HeaderParser {
public:
  std::optional<Y4mHeader> run(std::string_view line, std::string &error);

private:
  bool field(std::string_view token);
  bool size(char tag, std::string_view value, int &out);
  bool rate(std::string_view token, std::string_view value);
  bool interlacing(std::string_view token, std::string_view value);
  bool aspect(std::string_view token, std::string_view value);
  bool chroma(std::string_view token, std::string_view value);
  bool extension(std::string_view token);
  bool fail(std::string message) {
    error_ = std::move(message);
    return false;
  }

  Y4mHeader header_;
  std::array<bool, 128> seen_{};
  bool seen_range_ = false;
  std::string error_;
};

std::optional<Y4mHeader> HeaderParser::run(std::string_view line, std::string &error) {
  if (!line.starts_with(kY4mMagic)) {
    error = "does not start with YUV4MPEG2";
    return std::nullopt;
  }
  std::string_view rest = line.substr(kY4mMagic.size());
  while (!rest.empty()) {
    if (rest.front() != ' ') {
      error = "YUV4MPEG2 must be followed by a space, not '" + printable(rest.substr(0, 1)) + "'";
      return std::nullopt;
    }
    rest.remove_prefix(1);
    const std::string_view token = rest.substr(0, rest.find(' '));
    rest.remove_prefix(token.size());
    if (!field(token)) {
      error = error_;
      return std::nullopt;
    }
  }
  for (const char tag : {'W', 'H'})
    if (!seen_[static_cast<unsigned char>(tag)]) {
      error = std::string(1, tag) + " missing";
      return std::nullopt;
    }
  const std::string reason = base::check_video_format(y4m_video_format(header_));
  if (!reason.empty()) {
    error = "W" + std::to_string(header_.width) + " H" + std::to_string(header_.height) + " C" +
            std::string(chroma_name(header_.chroma)) + ": " + reason;
    return std::nullopt;
  }
  return header_;
}

bool HeaderParser::field(std::string_view token) {
  if (token.empty())
    return fail("empty field: two spaces in a row, or a space at the end of the line");
  const char tag = token.front();
  const std::string_view value = token.substr(1);
  if (tag == 'X')
    return extension(token);
  if (static_cast<unsigned char>(tag) >= seen_.size())
    return fail("'" + printable(token) + "' is not a Y4M field (W, H, F, I, A, C or X)");
  if (seen_[static_cast<unsigned char>(tag)])
    return fail(std::string(1, tag) + " given twice");
  seen_[static_cast<unsigned char>(tag)] = true;
  switch (tag) {
  case 'W':
    return size('W', value, header_.width);
  case 'H':
    return size('H', value, header_.height);
  case 'F':
    return rate(token, value);
  case 'I':
    return interlacing(token, value);
  case 'A':
    return aspect(token, value);
  case 'C':
    return chroma(token, value);
  default:
    return fail("'" + printable(token) + "' is not a Y4M field (W, H, F, I, A, C or X)");
  }
}

bool HeaderParser::size(char tag, std::string_view value, int &out) {
  std::uint32_t n = 0;
  if (!parse_uint(value, n) || n == 0 || n > INT_MAX)
    return fail(std::string(1, tag) + " '" + printable(value) + "' is not a positive whole number");
  out = static_cast<int>(n);
  return true;
}

bool HeaderParser::rate(std::string_view token, std::string_view value) {
  std::uint32_t num = 0, den = 0;
  if (!parse_ratio(value, num, den))
    return fail("F '" + printable(value) + "' is not a ratio N:D of whole numbers");
  if (num == 0 && den == 0)
    return true; // the spec's "unknown"
  if (num == 0 || den == 0)
    return fail(printable(token) + " is not a frame rate");
  const double fps = double(num) / double(den);
  if (fps < 0.01 || fps > 1000.0)
    return fail(printable(token) + " is outside 0.01 to 1000 frames a second");
  header_.rate_num = num;
  header_.rate_den = den;
  return true;
}

bool HeaderParser::interlacing(std::string_view token, std::string_view value) {
  if (value == "p")
    return true;
  if (value == "t" || value == "b")
    return fail(printable(token) + ": interlaced video is not supported, only progressive (Ip)");
  if (value == "m")
    return fail(printable(token) + ": mixed interlacing is not supported, only progressive (Ip)");
  if (value == "?")
    return fail(printable(token) + ": unknown interlacing is not supported, only progressive (Ip)");
  return fail("I '" + printable(value) + "' is not p, t, b, m or ?");
}

bool HeaderParser::aspect(std::string_view token, std::string_view value) {
  std::uint32_t num = 0, den = 0;
  if (!parse_ratio(value, num, den))
    return fail("A '" + printable(value) + "' is not a ratio N:D of whole numbers");
  if ((num == 0 && den == 0) || (num == den && num > 0))
    return true;
  return fail(printable(token) +
              ": non-square pixels are not supported (the renderer assumes square pixels)");
}

bool HeaderParser::chroma(std::string_view token, std::string_view value) {
  if (value == "420jpeg" || value == "420")
    header_.chroma = Y4mChroma::c420jpeg;
  else if (value == "420mpeg2")
    header_.chroma = Y4mChroma::c420mpeg2;
  else if (value == "420paldv")
    header_.chroma = Y4mChroma::c420paldv;
  else if (value == "422")
    header_.chroma = Y4mChroma::c422;
  else if (value.starts_with("mono"))
    return fail(printable(token) + ": greyscale is not supported; " + std::string(kChromaChoices));
  else if (value.starts_with("444"))
    return fail(printable(token) + ": 4:4:4 is not supported; " + std::string(kChromaChoices));
  else if (value.find('p') != std::string_view::npos)
    return fail(printable(token) + ": more than 8 bits a sample is not supported; " +
                std::string(kChromaChoices));
  else
    return fail(printable(token) + " is not supported; " + std::string(kChromaChoices));
  return true;
}

bool HeaderParser::extension(std::string_view token) {
  constexpr std::string_view kRange = "XCOLORRANGE=";
  if (!token.starts_with(kRange))
    return true; // XYSCSS and other writers' notes
  if (seen_range_)
    return fail("XCOLORRANGE given twice");
  seen_range_ = true;
  const std::string_view value = token.substr(kRange.size());
  if (value == "LIMITED")
    header_.range = base::ColorRange::limited;
  else if (value == "FULL")
    header_.range = base::ColorRange::full;
  else
    return fail(printable(token) + ": the range is FULL or LIMITED");
  return true;
}

} // namespace

std::optional<Y4mHeader> parse_y4m_header(std::string_view line, std::string &error) {
  return HeaderParser().run(line, error);
}

std::string format_y4m_header(const Y4mHeader &header) {
  return std::string(kY4mMagic) + " W" + std::to_string(header.width) + " H" +
         std::to_string(header.height) + " F" + std::to_string(header.rate_num) + ":" +
         std::to_string(header.rate_den) + " Ip A1:1 C" + std::string(chroma_name(header.chroma)) +
         " XCOLORRANGE=" + (header.range == base::ColorRange::full ? "FULL" : "LIMITED") + "\n";
}

base::VideoFormat y4m_video_format(const Y4mHeader &header) {
  base::VideoFormat format;
  format.pixel =
      header.chroma == Y4mChroma::c422 ? base::PixelFormat::yuyv : base::PixelFormat::nv12;
  format.width = header.width;
  format.height = header.height;
  format.matrix = base::ColorMatrix::bt709;
  format.range = header.range;
  return format;
}

std::optional<Y4mRate> y4m_rate_from_fps(double fps) {
  if (!std::isfinite(fps) || fps < 0.01 || fps > 1000.0)
    return std::nullopt;
  const double whole = std::round(fps);
  if (std::abs(fps - whole) < 1e-9 * fps)
    return Y4mRate{static_cast<std::uint32_t>(whole), 1};
  // 30000/1001 and its rounded spelling 29.97 both mean NTSC's rate.
  const double ntsc = fps * 1.001;
  if (std::abs(ntsc - std::round(ntsc)) < 1e-4)
    return Y4mRate{static_cast<std::uint32_t>(std::round(ntsc)) * 1000, 1001};
  const auto thousandths = static_cast<std::uint32_t>(std::llround(fps * 1000.0));
  const std::uint32_t common = std::gcd(thousandths, 1000u);
  return Y4mRate{thousandths / common, 1000 / common};
}

std::int64_t y4m_frame_interval_ns(std::uint32_t num, std::uint32_t den) {
  if (num == 0 || den == 0)
    return 0;
  // 1e9 * 2^32 < 2^63: exact in 64 bits.
  return (std::int64_t{1'000'000'000} * den + num / 2) / num;
}

} // namespace camhead::hal::video_file
