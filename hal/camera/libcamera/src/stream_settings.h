// The libcamera backend's pure parts: camhead's pixel formats as libcamera's
// (DRM) fourccs, the words its errors use for a stream configuration, the
// options' checks, colour, and where a frame lies in a buffer's planes.
// No libcamera header here, so that the unit tests run where libcamera is
// not installed; the module checks the fourccs against <libcamera/formats.h>
// at compile time.
//
// libcamera names RGB formats by a little-endian word, as DRM does: its
// RGB888 is B, G, R in memory (camhead bgr24, V4L2 BGR24) and its BGR888 is
// R, G, B (camhead rgb24, V4L2 RGB24).
//
// Thread safety: plain functions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "camhead/base/video_format.h"
#include "camhead/hal/camera/libcamera/libcamera_camera.h"

namespace camhead::hal::camera::libcamera_settings {

[[nodiscard]] constexpr std::uint32_t fourcc(char a, char b, char c, char d) {
  return std::uint32_t(std::uint8_t(a)) | std::uint32_t(std::uint8_t(b)) << 8 |
         std::uint32_t(std::uint8_t(c)) << 16 | std::uint32_t(std::uint8_t(d)) << 24;
}

inline constexpr std::uint32_t kYuyv = fourcc('Y', 'U', 'Y', 'V');
inline constexpr std::uint32_t kNv12 = fourcc('N', 'V', '1', '2');
inline constexpr std::uint32_t kRgb888 = fourcc('R', 'G', '2', '4'); // B G R bytes
inline constexpr std::uint32_t kBgr888 = fourcc('B', 'G', '2', '4'); // R G B bytes

// The libcamera format for a camhead one; nullopt for xrgb8888 (a display
// format: cameras give the other four, as the V4L2 backend says too).
[[nodiscard]] std::optional<std::uint32_t> libcamera_fourcc(base::PixelFormat format);
// The camhead format with the same bytes, nullopt where camhead has none.
[[nodiscard]] std::optional<base::PixelFormat> camhead_format(std::uint32_t fourcc);
// "RGB888", "NV12", ... as libcamera prints them; others as their four
// characters ("MJPG") or, unprintable, in hex.
[[nodiscard]] std::string libcamera_format_name(std::uint32_t fourcc);

// What a stream configuration asks for or answers with.
struct StreamShape {
  std::uint32_t fourcc = 0;
  int width = 0;
  int height = 0;
  bool operator==(const StreamShape &) const = default;
};

// "636x480 RGB888 (camhead bgr24)", "1280x720 MJPG (no camhead format)".
[[nodiscard]] std::string describe(const StreamShape &shape);

// How messages name a camera: "'Sensor B' (platform/vimc.0 Sensor B)", as
// `cam -l` does; "(ID)" alone where the camera has no model.
[[nodiscard]] std::string camera_label(const std::string &id, const std::string &model);

// Why open fails when validate() changed the format or size: names the
// camera, both configurations and what to do.
[[nodiscard]] std::string adjusted_message(const std::string &camera, const StreamShape &asked,
                                           const StreamShape &answered);

// Why the options cannot be opened (format, size, buffer count), or empty.
[[nodiscard]] std::string check_options(const LibcameraCameraOptions &options);

// libcamera's ColorSpace, the two fields camhead uses.
enum class YcbcrEncoding { none, rec601, rec709, rec2020 };
struct StreamColour {
  YcbcrEncoding encoding = YcbcrEncoding::none;
  bool full_range = false;
};

// The matrix and range of a YUV stream: what libcamera says where it says
// (BT.2020 is taken as BT.709, the nearest camhead decodes), else BT.601
// limited up to 576 lines and BT.709 limited above, as the V4L2 backend.
void apply_colour(base::VideoFormat &format, const std::optional<StreamColour> &colour);

// One plane of a libcamera FrameBuffer: its dmabuf, and where it lies in it.
struct Plane {
  int fd = -1;
  std::size_t offset = 0;
  std::size_t length = 0;
};

// Where a whole frame of `format` lies: one mapping of `map_length` bytes
// from the start of `fd`, the frame at `frame_offset` in it.
struct FrameRegion {
  int fd = -1;
  std::size_t map_length = 0;
  std::size_t frame_offset = 0;
};

// The region of a buffer's planes that holds the frame camhead reads in one
// piece (NV12's chroma right after its luma, in the same dmabuf), or empty
// with `error` saying why not (planes in separate dmabufs, planes too small).
[[nodiscard]] std::optional<FrameRegion>
frame_region(const std::vector<Plane> &planes, const base::VideoFormat &format, std::string &error);

} // namespace camhead::hal::camera::libcamera_settings
