// See device_file.h.
#include "camhead/hal/device_file.h"

#include <array>
#include <cstring>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace camhead::hal {

std::string errno_text(int err) {
  std::array<char, 128> buffer{};
  // The GNU strerror_r returns the text, which need not be in `buffer`.
  return ::strerror_r(err, buffer.data(), buffer.size());
}

DeviceFile &DeviceFile::operator=(DeviceFile &&other) noexcept {
  if (this != &other) {
    close();
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

void DeviceFile::close() {
  // Not retried on EINTR: Linux has released the descriptor whatever close returns.
  if (fd_ >= 0)
    ::close(std::exchange(fd_, -1));
}

DeviceFile open_device_node(const std::string &path, int flags, std::string &error) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) {
    error = "cannot open: " + errno_text(errno);
    return {};
  }
  DeviceFile file(fd);
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    error = "cannot check it: " + errno_text(errno);
    return {};
  }
  if (!S_ISCHR(st.st_mode)) {
    error = "is not a device node";
    return {};
  }
  return file;
}

} // namespace camhead::hal
