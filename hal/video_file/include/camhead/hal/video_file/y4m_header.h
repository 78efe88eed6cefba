// The YUV4MPEG2 (Y4M) stream header, as the file camera reads it and the Y4M
// sink writes it. The reader is strict: a field it does not understand is an
// error, not a guess, because a wrong guess shows as a picture that is subtly
// off (shifted chroma, washed-out levels) rather than as an error.
//
// Accepted: W, H (required), F (N:D, 0:0 = unknown), I (p only; a missing I
// is taken as progressive, as mjpegtools does), A (1:1, or 0:0 = unknown:
// the renderer assumes square pixels, so other ratios are refused), C
// (420jpeg, 420mpeg2, 420paldv, 420, 422; missing = 420jpeg, the spec's
// default), X parameters (XCOLORRANGE=FULL|LIMITED is used, the others such
// as mjpegtools' XYSCSS are ignored). Y4M has no field for the colour
// matrix; bt709 is assumed. The 4:2:0 sitings differ by half a chroma pixel
// and are all delivered as they are, without resampling.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "camhead/base/video_format.h"

namespace camhead::hal::video_file {

inline constexpr std::string_view kY4mMagic = "YUV4MPEG2";
// Real headers are under 100 bytes; the bound keeps a file without a newline
// from being read as one endless header.
inline constexpr std::size_t kY4mMaxHeaderBytes = 1024;
inline constexpr std::size_t kY4mMaxFrameHeaderBytes = 256;

enum class Y4mChroma { c420jpeg, c420mpeg2, c420paldv, c422 };

struct Y4mHeader {
  int width = 0;
  int height = 0;
  std::uint32_t rate_num = 0; // F rate_num:rate_den; 0:0 = unknown
  std::uint32_t rate_den = 0;
  Y4mChroma chroma = Y4mChroma::c420jpeg;
  base::ColorRange range = base::ColorRange::limited;
};

// Parses the header line without its '\n'. On failure, `error` names the
// field first: "W missing", "C444 is not supported: ...".
[[nodiscard]] std::optional<Y4mHeader> parse_y4m_header(std::string_view line, std::string &error);

// The header line with its '\n', fields in ffmpeg's order:
// "YUV4MPEG2 W4 H2 F25:1 Ip A1:1 C422 XCOLORRANGE=LIMITED\n" (ffmpeg also
// writes mjpegtools' redundant XYSCSS=422; no reader needs it).
[[nodiscard]] std::string format_y4m_header(const Y4mHeader &header);

// The packed format the planes are delivered in: nv12 for 4:2:0, yuyv for
// 4:2:2, bt709, the header's range.
[[nodiscard]] base::VideoFormat y4m_video_format(const Y4mHeader &header);

// F as a ratio: whole rates as N:1, the NTSC family (29.97, 23.976, 59.94)
// as N*1000:1001, anything else in thousandths. Empty unless 0.01 <= fps <=
// 1000.
struct Y4mRate {
  std::uint32_t num = 0;
  std::uint32_t den = 0;
};
[[nodiscard]] std::optional<Y4mRate> y4m_rate_from_fps(double fps);

// Nanoseconds between frames at num:den frames a second, rounded; 0 for an
// unknown rate.
[[nodiscard]] std::int64_t y4m_frame_interval_ns(std::uint32_t num, std::uint32_t den);

} // namespace camhead::hal::video_file
