#include "service_notifier.h"

#include <cerrno>
#include <charconv>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace camhead::pipeline {
namespace {

// The address of `path`, its length for sendto(); an abstract name ('@')
// starts with a NUL byte and is not NUL-terminated.
socklen_t socket_address(const std::string &path, sockaddr_un &address) {
  address = {};
  address.sun_family = AF_UNIX;
  std::memcpy(address.sun_path, path.data(), path.size());
  if (path[0] == '@')
    address.sun_path[0] = '\0';
  return socklen_t(offsetof(sockaddr_un, sun_path) + path.size());
}

std::optional<std::uint64_t> parse_unsigned(const char *text) {
  if (text == nullptr || *text == '\0')
    return std::nullopt;
  std::uint64_t value = 0;
  const char *end = text + std::strlen(text);
  const auto [stop, error] = std::from_chars(text, end, value);
  if (error != std::errc() || stop != end)
    return std::nullopt;
  return value;
}

} // namespace

ServiceNotifier::ServiceNotifier(std::string socket_path,
                                 std::optional<std::chrono::microseconds> watchdog_timeout)
    : socket_path_(std::move(socket_path)), watchdog_timeout_(watchdog_timeout) {
  if (socket_path_.empty() || (socket_path_[0] != '/' && socket_path_[0] != '@'))
    throw std::invalid_argument("NOTIFY_SOCKET '" + socket_path_ +
                                "': not an absolute path nor an abstract socket ('@name')");
  if (socket_path_.size() > sizeof(sockaddr_un::sun_path) - 1)
    throw std::invalid_argument("NOTIFY_SOCKET '" + socket_path_ + "': longer than the " +
                                std::to_string(sizeof(sockaddr_un::sun_path) - 1) +
                                " bytes a socket address holds");
  fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd_ < 0)
    throw std::runtime_error(std::string("NOTIFY_SOCKET: socket(): ") + std::strerror(errno));
}

ServiceNotifier::~ServiceNotifier() {
  if (fd_ >= 0)
    ::close(fd_);
}

ServiceNotifier ServiceNotifier::from_environment() {
  const char *socket_path = std::getenv("NOTIFY_SOCKET");
  if (socket_path == nullptr || *socket_path == '\0')
    return {};
  std::optional<std::chrono::microseconds> watchdog;
  if (const char *usec = std::getenv("WATCHDOG_USEC")) {
    const std::optional<std::uint64_t> value = parse_unsigned(usec);
    const char *pid_text = std::getenv("WATCHDOG_PID");
    const std::optional<std::uint64_t> pid = parse_unsigned(pid_text);
    if (!value || *value == 0 || (pid_text != nullptr && !pid))
      std::fprintf(stderr, "camhead: ignoring WATCHDOG_USEC='%s' WATCHDOG_PID='%s'\n", usec,
                   pid_text != nullptr ? pid_text : "");
    else if (!pid || *pid == std::uint64_t(::getpid()))
      watchdog = std::chrono::microseconds(*value);
  }
  try {
    return ServiceNotifier(socket_path, watchdog);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "camhead: %s; not notifying the service manager\n", e.what());
    return {};
  }
}

bool ServiceNotifier::notify(std::string_view state) const {
  if (fd_ < 0)
    return false;
  sockaddr_un address;
  const socklen_t length = socket_address(socket_path_, address);
  const ssize_t sent = ::sendto(fd_, state.data(), state.size(), MSG_NOSIGNAL,
                                reinterpret_cast<const sockaddr *>(&address), length);
  return sent == ssize_t(state.size());
}

} // namespace camhead::pipeline
