// See pixel_formats.h.
#include "camhead/hal/v4l2/pixel_formats.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <utility>

namespace camhead::hal::v4l2 {
namespace {

constexpr std::array<std::pair<base::PixelFormat, std::uint32_t>, 4> kFourccs = {{
    {base::PixelFormat::yuyv, V4L2_PIX_FMT_YUYV},
    {base::PixelFormat::nv12, V4L2_PIX_FMT_NV12},
    {base::PixelFormat::rgb24, V4L2_PIX_FMT_RGB24},
    {base::PixelFormat::bgr24, V4L2_PIX_FMT_BGR24},
}};

const char *field_text(std::uint32_t field) {
  switch (field) {
  case V4L2_FIELD_ANY:
    return "any";
  case V4L2_FIELD_NONE:
    return "progressive";
  case V4L2_FIELD_TOP:
    return "top field only";
  case V4L2_FIELD_BOTTOM:
    return "bottom field only";
  case V4L2_FIELD_INTERLACED:
  case V4L2_FIELD_INTERLACED_TB:
  case V4L2_FIELD_INTERLACED_BT:
    return "interlaced";
  case V4L2_FIELD_SEQ_TB:
  case V4L2_FIELD_SEQ_BT:
    return "fields one after the other";
  case V4L2_FIELD_ALTERNATE:
    return "alternate fields";
  }
  return "unknown field order";
}

const char *encoding_text(std::uint32_t enc) {
  switch (enc) {
  case V4L2_YCBCR_ENC_BT2020:
    return "BT.2020";
  case V4L2_YCBCR_ENC_BT2020_CONST_LUM:
    return "BT.2020 constant luminance";
  case V4L2_YCBCR_ENC_SMPTE240M:
    return "SMPTE 240M";
  }
  return "an unknown one";
}

} // namespace

std::optional<std::uint32_t> fourcc_of(base::PixelFormat format) {
  for (const auto &[pixel, fourcc] : kFourccs)
    if (pixel == format)
      return fourcc;
  return std::nullopt;
}

std::optional<base::PixelFormat> pixel_format_of(std::uint32_t fourcc) {
  for (const auto &[pixel, code] : kFourccs)
    if (code == fourcc)
      return pixel;
  return std::nullopt;
}

std::string fourcc_text(std::uint32_t fourcc) {
  std::string text;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
    if (c < 0x20 || c > 0x7e) {
      std::array<char, 16> hex{};
      std::snprintf(hex.data(), hex.size(), "0x%08x", fourcc);
      return hex.data();
    }
    text += c;
  }
  // Big-endian variants set the top bit, which is not a letter.
  while (!text.empty() && text.back() == ' ')
    text.pop_back();
  return text;
}

bool is_jpeg(std::uint32_t fourcc) {
  return fourcc == V4L2_PIX_FMT_MJPEG || fourcc == V4L2_PIX_FMT_JPEG;
}

std::string describe(const v4l2_pix_format &pix) {
  std::string text = std::to_string(pix.width) + "x" + std::to_string(pix.height) + " " +
                     fourcc_text(pix.pixelformat);
  if (pix.field != V4L2_FIELD_NONE)
    text += std::string(" (") + field_text(pix.field) + ")";
  return text;
}

bool is_whole_frame(std::uint32_t field) {
  return field == V4L2_FIELD_NONE || field == V4L2_FIELD_INTERLACED ||
         field == V4L2_FIELD_INTERLACED_TB || field == V4L2_FIELD_INTERLACED_BT;
}

std::optional<Colour> colour_of(const v4l2_pix_format &pix, std::string &error) {
  const bool extended = pix.priv == V4L2_PIX_FMT_PRIV_MAGIC;
  const std::uint32_t colorspace = pix.colorspace;
  std::uint32_t enc = extended ? pix.ycbcr_enc : std::uint32_t{V4L2_YCBCR_ENC_DEFAULT};
  std::uint32_t quantization =
      extended ? pix.quantization : std::uint32_t{V4L2_QUANTIZATION_DEFAULT};
  if (enc == V4L2_YCBCR_ENC_DEFAULT) {
    if (colorspace != V4L2_COLORSPACE_DEFAULT)
      enc = V4L2_MAP_YCBCR_ENC_DEFAULT(colorspace);
    else
      enc = pix.height <= 576 ? V4L2_YCBCR_ENC_601 : V4L2_YCBCR_ENC_709;
  }
  if (quantization == V4L2_QUANTIZATION_DEFAULT)
    quantization = V4L2_MAP_QUANTIZATION_DEFAULT(false, colorspace, enc);

  Colour colour;
  switch (enc) {
  case V4L2_YCBCR_ENC_601:
  case V4L2_YCBCR_ENC_XV601: // xvYCC: BT.601's matrix, codes beyond the nominal range
    colour.matrix = base::ColorMatrix::bt601;
    break;
  case V4L2_YCBCR_ENC_709:
  case V4L2_YCBCR_ENC_XV709:
    colour.matrix = base::ColorMatrix::bt709;
    break;
  default:
    error = std::string("Y'CbCr encoding ") + encoding_text(enc) +
            " cannot be converted (camhead converts BT.601 and BT.709)";
    return std::nullopt;
  }
  colour.range = quantization == V4L2_QUANTIZATION_FULL_RANGE ? base::ColorRange::full
                                                              : base::ColorRange::limited;
  return colour;
}

void set_colour(v4l2_pix_format &pix, const base::VideoFormat &format) {
  pix.priv = V4L2_PIX_FMT_PRIV_MAGIC;
  if (!base::is_yuv(format.pixel)) {
    pix.colorspace = V4L2_COLORSPACE_SRGB;
    pix.ycbcr_enc = V4L2_YCBCR_ENC_DEFAULT;
    pix.quantization = V4L2_QUANTIZATION_FULL_RANGE;
    return;
  }
  const bool bt709 = format.matrix == base::ColorMatrix::bt709;
  pix.colorspace = bt709 ? V4L2_COLORSPACE_REC709 : V4L2_COLORSPACE_SMPTE170M;
  pix.ycbcr_enc = bt709 ? V4L2_YCBCR_ENC_709 : V4L2_YCBCR_ENC_601;
  pix.quantization = format.range == base::ColorRange::full ? V4L2_QUANTIZATION_FULL_RANGE
                                                            : V4L2_QUANTIZATION_LIM_RANGE;
  pix.xfer_func = V4L2_XFER_FUNC_709;
}

std::optional<v4l2_fract> frame_period(double fps) {
  if (!std::isfinite(fps) || fps <= 0 || fps > 1000)
    return std::nullopt;
  // NTSC-derived rates are N/1.001 exactly: 30000/1001, not 2997/100.
  const double ntsc = fps * 1.001;
  if (std::abs(ntsc - std::round(ntsc)) < 5e-4 && std::abs(fps - std::round(fps)) > 1e-3)
    return v4l2_fract{1001, static_cast<std::uint32_t>(std::lround(ntsc) * 1000)};
  const auto milli = static_cast<std::uint32_t>(std::lround(fps * 1000));
  if (milli == 0)
    return std::nullopt;
  const std::uint32_t divisor = std::gcd(1000u, milli);
  return v4l2_fract{1000 / divisor, milli / divisor};
}

std::int64_t period_ns(const v4l2_fract &period) {
  if (period.numerator == 0 || period.denominator == 0)
    return 0;
  return std::llround(1e9 * period.numerator / period.denominator);
}

std::string rate_text(const v4l2_fract &period) {
  if (period.numerator == 0 || period.denominator == 0)
    return "an unknown rate";
  std::array<char, 32> text{};
  std::snprintf(text.data(), text.size(), "%.3f",
                static_cast<double>(period.denominator) / period.numerator);
  std::string s = text.data();
  while (s.back() == '0')
    s.pop_back();
  if (s.back() == '.')
    s.pop_back();
  return s + " fps";
}

} // namespace camhead::hal::v4l2
