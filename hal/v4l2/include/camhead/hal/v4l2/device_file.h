// A V4L2 device node as the camera and the loopback sink hold it: the file
// descriptor with its owner (closed once), ioctls retried when a signal
// interrupts them, and what the driver says it is. Errors are values, the
// reason alone ("cannot open: No such file or directory"); the caller adds
// the device's name, since the backends must not throw once open.
//
// Thread safety: a DeviceFile is one thread's, or guarded by its owner;
// ioctl() may be called from several threads at once (the kernel serialises
// them), close() only while no other thread uses the descriptor.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "camhead/hal/device_file.h"

namespace camhead::hal::v4l2 {

using hal::DeviceFile;
using hal::errno_text;

// Opens `path` (a /dev node or a udev link to one, followed) read-write,
// non-blocking, close-on-exec. Refuses what is not a character device, so a
// regular file named by mistake is not truncated or written to.
[[nodiscard]] DeviceFile open_device(const std::string &path, std::string &error);

// VIDIOC_QUERYCAP. `caps` are the capabilities of this node (device_caps
// where the driver gives them, not those of the whole device).
struct DeviceInfo {
  std::string driver; // "vivid", "uvcvideo", "v4l2 loopback"
  std::string card;
  std::string bus;
  std::uint32_t caps = 0;
};
// Empty with `error` when the node does not answer QUERYCAP: "not a V4L2
// device (VIDIOC_QUERYCAP: Inappropriate ioctl for device)".
[[nodiscard]] std::optional<DeviceInfo> query_device(const DeviceFile &file, std::string &error);

// "video capture, streaming" for messages: the capability bits camhead
// cares about, in words.
[[nodiscard]] std::string caps_text(std::uint32_t caps);

// True for the errors that mean the device itself is gone (unplugged, its
// driver unbound or unloaded), not that one request failed.
[[nodiscard]] bool is_device_gone(int err);

} // namespace camhead::hal::v4l2
