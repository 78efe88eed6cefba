// systemd's service notification protocol (sd_notify(3)), without
// libsystemd: each message is one datagram of newline-separated VAR=VALUE
// assignments to the AF_UNIX socket named by $NOTIFY_SOCKET (a path, or an
// abstract socket when it starts with '@'). `camhead run` under
// systemd/camhead@.service says READY=1 after its first output frame,
// STATUS= with what its status line shows, WATCHDOG=1 while its output
// really advances (output_watchdog.h) and STOPPING=1 at the end; in a
// terminal, where the variable is unset, every call does nothing.
//
// Thread safety: notify() may be called from any thread; a message is one
// send() that never blocks (a full socket loses the message, as sd_notify's
// does; systemd drains it).
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <string_view>

namespace camhead::pipeline {

class ServiceNotifier {
public:
  // No socket: every notify() returns false, watchdog_interval() none.
  ServiceNotifier() = default;
  // To `socket_path` ("@name": abstract), with the watchdog's timeout if
  // systemd asks for one. Throws std::invalid_argument for a path longer
  // than a socket address holds or not absolute (nor abstract), naming it.
  explicit ServiceNotifier(std::string socket_path,
                           std::optional<std::chrono::microseconds> watchdog_timeout = {});
  ~ServiceNotifier();
  ServiceNotifier(const ServiceNotifier &) = delete;
  ServiceNotifier &operator=(const ServiceNotifier &) = delete;

  // From systemd's environment: NOTIFY_SOCKET, and WATCHDOG_USEC where
  // WATCHDOG_PID is unset or this process's. A malformed variable is
  // ignored as systemd's own library ignores it, and said on stderr.
  static ServiceNotifier from_environment();

  [[nodiscard]] bool active() const { return fd_ >= 0; }
  // How often the service must say WATCHDOG=1 (systemd's timeout); none
  // when systemd watches nothing.
  [[nodiscard]] std::optional<std::chrono::microseconds> watchdog_timeout() const {
    return watchdog_timeout_;
  }
  // Sends `state` ("READY=1", "STATUS=...\nWATCHDOG=1"); false if there is
  // no socket or the datagram did not go.
  bool notify(std::string_view state) const;

private:
  int fd_ = -1;
  std::string socket_path_;
  std::optional<std::chrono::microseconds> watchdog_timeout_;
};

} // namespace camhead::pipeline
