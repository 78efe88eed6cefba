// A device node's descriptor as the V4L2 and DRM backends hold it: closed
// once, moved not copied, ioctls retried while a signal interrupts them,
// and opened only if it is a character device, so that a regular file named
// by mistake is never written to.
//
// Thread safety: as a file descriptor; its users guard it.
#pragma once

#include <cerrno>
#include <string>

#include <sys/ioctl.h>

namespace camhead::hal {

// strerror(err), thread-safe.
[[nodiscard]] std::string errno_text(int err);

class DeviceFile {
public:
  DeviceFile() = default;
  explicit DeviceFile(int fd) : fd_(fd) {}
  ~DeviceFile() { close(); }
  DeviceFile(DeviceFile &&other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  DeviceFile &operator=(DeviceFile &&other) noexcept;
  DeviceFile(const DeviceFile &) = delete;
  DeviceFile &operator=(const DeviceFile &) = delete;

  [[nodiscard]] int fd() const { return fd_; }
  [[nodiscard]] bool is_open() const { return fd_ >= 0; }
  void close();

  // ioctl(fd, request, &arg), again while EINTR; false with errno set.
  // EAGAIN is an answer (V4L2's "no buffer yet"), except where
  // `retry_again` says the driver means "try again" (DRM's contended
  // mode-setting locks).
  template <class Arg>
  [[nodiscard]] bool ioctl(unsigned long request, Arg &arg, bool retry_again = false) const {
    int result = 0;
    do {
      result = ::ioctl(fd_, request, &arg);
    } while (result < 0 && (errno == EINTR || (retry_again && errno == EAGAIN)));
    return result == 0;
  }

private:
  int fd_ = -1;
};

// Opens `path` (a /dev node, or a udev link to one, followed) with `flags`
// and O_CLOEXEC. Empty with `error` ("cannot open: REASON", "is not a
// device node") otherwise.
[[nodiscard]] DeviceFile open_device_node(const std::string &path, int flags, std::string &error);

} // namespace camhead::hal
