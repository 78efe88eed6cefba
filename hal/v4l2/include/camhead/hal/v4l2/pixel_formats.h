// Between V4L2's single-planar formats and camhead's VideoFormat: FourCCs,
// the Y'CbCr matrix and range, whole frames versus fields, and frame rates
// as V4L2's timeperframe fractions. Pure functions; the unit tests cover them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <linux/videodev2.h>

#include "camhead/base/video_format.h"

namespace camhead::hal::v4l2 {

// V4L2_PIX_FMT_YUYV, _NV12, _RGB24, _BGR24 for the formats a V4L2 device
// carries for camhead; empty for xrgb8888 (a display format).
[[nodiscard]] std::optional<std::uint32_t> fourcc_of(base::PixelFormat format);
[[nodiscard]] std::optional<base::PixelFormat> pixel_format_of(std::uint32_t fourcc);

// "YUYV", "MJPG"; a code with unprintable bytes as 0x%08x.
[[nodiscard]] std::string fourcc_text(std::uint32_t fourcc);

// MJPEG and JPEG: what webcams offer at high resolutions, and camhead cannot
// decode yet.
[[nodiscard]] bool is_jpeg(std::uint32_t fourcc);

// "640x480 YUYV" (and the field order when it is not progressive).
[[nodiscard]] std::string describe(const v4l2_pix_format &pix);

// A buffer holds a whole frame: progressive, or both fields woven into one
// picture (what SD capture cards deliver). Single fields, and the two
// fields one after the other, are not frames.
[[nodiscard]] bool is_whole_frame(std::uint32_t field);

struct Colour {
  base::ColorMatrix matrix = base::ColorMatrix::bt709;
  base::ColorRange range = base::ColorRange::limited;
};

// What a Y'CbCr format from the driver means. The driver's ycbcr_enc and
// quantization where it sets them; else what V4L2 defines for its
// colorspace (V4L2_MAP_YCBCR_ENC_DEFAULT and _QUANTIZATION_DEFAULT: BT.709
// for REC709 and DCI-P3, BT.601 for SMPTE 170M, 470 BG and sRGB, as UVC
// webcams report, full range for JPEG); and where it says neither, BT.601
// limited up to 576 lines and BT.709 limited above (SD and HD video).
// Empty with `error` for an encoding camhead cannot convert (BT.2020,
// SMPTE 240M). Extended fields the driver did not fill (priv is not
// V4L2_PIX_FMT_PRIV_MAGIC) count as unset.
[[nodiscard]] std::optional<Colour> colour_of(const v4l2_pix_format &pix, std::string &error);

// The colorspace, ycbcr_enc and quantization that describe `format`, for a
// format camhead sets (the loopback sink).
void set_colour(v4l2_pix_format &pix, const base::VideoFormat &format);

// The frame period for `fps`: 1001/30000 for 29.97 (and the other /1.001
// rates), else 1000/round(1000 fps) reduced. Empty unless 0 < fps <= 1000.
[[nodiscard]] std::optional<v4l2_fract> frame_period(double fps);
// The period in nanoseconds; 0 for a fraction that is not one (0/0, x/0).
[[nodiscard]] std::int64_t period_ns(const v4l2_fract &period);
// "25 fps", "29.97 fps" for messages.
[[nodiscard]] std::string rate_text(const v4l2_fract &period);

} // namespace camhead::hal::v4l2
