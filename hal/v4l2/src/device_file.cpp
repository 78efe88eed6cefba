// See device_file.h.
#include "camhead/hal/v4l2/device_file.h"

#include <array>
#include <cerrno>
#include <utility>

#include <fcntl.h>
#include <linux/videodev2.h>

namespace camhead::hal::v4l2 {
namespace {

std::string c_string(const unsigned char *text, std::size_t size) {
  std::size_t n = 0;
  while (n < size && text[n] != 0)
    ++n;
  return std::string(reinterpret_cast<const char *>(text), n);
}

} // namespace

DeviceFile open_device(const std::string &path, std::string &error) {
  if (path.empty()) {
    error = "no device named";
    return {};
  }
  DeviceFile file = open_device_node(path, O_RDWR | O_NONBLOCK, error);
  if (!file.is_open() && error == "is not a device node")
    error += " (not a V4L2 device)";
  return file;
}

std::optional<DeviceInfo> query_device(const DeviceFile &file, std::string &error) {
  v4l2_capability cap{};
  if (!file.ioctl(VIDIOC_QUERYCAP, cap)) {
    const int err = errno;
    error = err == ENOTTY || err == EINVAL
                ? "not a V4L2 device (VIDIOC_QUERYCAP: " + errno_text(err) + ")"
                : "VIDIOC_QUERYCAP: " + errno_text(err);
    return std::nullopt;
  }
  DeviceInfo info;
  info.driver = c_string(cap.driver, sizeof cap.driver);
  info.card = c_string(cap.card, sizeof cap.card);
  info.bus = c_string(cap.bus_info, sizeof cap.bus_info);
  info.caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
  return info;
}

std::string caps_text(std::uint32_t caps) {
  static constexpr std::array<std::pair<std::uint32_t, const char *>, 6> kNames = {{
      {V4L2_CAP_VIDEO_CAPTURE, "video capture"},
      {V4L2_CAP_VIDEO_CAPTURE_MPLANE, "multi-planar video capture"},
      {V4L2_CAP_VIDEO_OUTPUT, "video output"},
      {V4L2_CAP_VIDEO_OUTPUT_MPLANE, "multi-planar video output"},
      {V4L2_CAP_STREAMING, "streaming"},
      {V4L2_CAP_READWRITE, "read/write"},
  }};
  std::string text;
  for (const auto &[bit, name] : kNames) {
    if ((caps & bit) == 0)
      continue;
    if (!text.empty())
      text += ", ";
    text += name;
  }
  return text.empty() ? "no video capture or output" : text;
}

bool is_device_gone(int err) {
  return err == ENODEV || err == ENXIO || err == EBADF;
}

} // namespace camhead::hal::v4l2
