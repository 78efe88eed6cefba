// `camhead run` as a systemd service (service/service_notifier.h,
// service/output_watchdog.h): the notify protocol against a socket the test
// owns, as systemd's is, and the watchdog that only a really advancing
// output feeds.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include "run/run_loop.h"
#include "run_test_support.h"
#include "service/output_watchdog.h"
#include "service/service_notifier.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// systemd's end of the protocol: a datagram socket bound to `path` ("@..."
// abstract), each message read whole.
class NotifySocket {
public:
  explicit NotifySocket(const std::string &path) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::memcpy(address.sun_path, path.data(), path.size());
    if (path[0] == '@')
      address.sun_path[0] = '\0';
    const socklen_t length = socklen_t(offsetof(sockaddr_un, sun_path) + path.size());
    if (::bind(fd_, reinterpret_cast<const sockaddr *>(&address), length) != 0)
      ADD_FAILURE() << "bind " << path << ": " << std::strerror(errno);
  }
  ~NotifySocket() { ::close(fd_); }

  // The next message, waiting at most `timeout`.
  std::optional<std::string> receive(std::chrono::milliseconds timeout = 2000ms) const {
    timeval tv{long(timeout.count() / 1000), long(timeout.count() % 1000) * 1000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    char buffer[4096];
    const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
    if (n < 0)
      return std::nullopt;
    return std::string(buffer, std::size_t(n));
  }

  // Every message until STOPPING=1 (or none for 5 s).
  std::vector<std::string> until_stopping() const {
    std::vector<std::string> messages;
    while (std::optional<std::string> m = receive(5000ms)) {
      messages.push_back(*m);
      if (*m == "STOPPING=1")
        break;
    }
    return messages;
  }

private:
  int fd_ = -1;
};

class Service : public RunLoop {};

TEST_F(Service, NotifiesAPathSocketAndAnAbstractOne) {
  const std::string path = (dir_ / "notify").string();
  const NotifySocket systemd(path);
  const ServiceNotifier notifier(path);
  ASSERT_TRUE(notifier.active());
  EXPECT_TRUE(notifier.notify("READY=1"));
  EXPECT_EQ(systemd.receive(), "READY=1");
  EXPECT_TRUE(notifier.notify("STATUS=in 25.0 fps\nWATCHDOG=1"));
  EXPECT_EQ(systemd.receive(), "STATUS=in 25.0 fps\nWATCHDOG=1");

  const std::string abstract = "@camhead-test-" + std::to_string(::getpid());
  const NotifySocket abstract_systemd(abstract);
  const ServiceNotifier abstract_notifier(abstract);
  EXPECT_TRUE(abstract_notifier.notify("READY=1"));
  EXPECT_EQ(abstract_systemd.receive(), "READY=1");
}

TEST_F(Service, WithoutASocketNothingIsSent) {
  const ServiceNotifier none;
  EXPECT_FALSE(none.active());
  EXPECT_FALSE(none.notify("READY=1"));
  EXPECT_FALSE(none.watchdog_timeout());
  // A socket nobody listens on: the datagram does not go, and says so.
  const ServiceNotifier nobody((dir_ / "nobody").string());
  EXPECT_FALSE(nobody.notify("READY=1"));
}

TEST_F(Service, RefusesASocketPathItCannotUseNamingIt) {
  for (const std::string &bad : {std::string("relative/notify"), std::string(200, '/')}) {
    try {
      const ServiceNotifier notifier(bad);
      ADD_FAILURE() << "took '" << bad << "'";
    } catch (const std::invalid_argument &e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

// systemd says the watchdog's timeout in WATCHDOG_USEC, and which process
// it means in WATCHDOG_PID (another's: not this one's business).
TEST_F(Service, TheWatchdogIsTheEnvironmentsForThisProcessOnly) {
  const std::string path = (dir_ / "notify").string();
  const NotifySocket systemd(path);
  ::setenv("NOTIFY_SOCKET", path.c_str(), 1);
  ::setenv("WATCHDOG_USEC", "3000000", 1);
  ::unsetenv("WATCHDOG_PID");
  EXPECT_EQ(ServiceNotifier::from_environment().watchdog_timeout(), 3s);
  ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
  EXPECT_EQ(ServiceNotifier::from_environment().watchdog_timeout(), 3s);
  ::setenv("WATCHDOG_PID", std::to_string(::getpid() + 1).c_str(), 1);
  EXPECT_FALSE(ServiceNotifier::from_environment().watchdog_timeout());
  ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
  ::setenv("WATCHDOG_USEC", "soon", 1);
  EXPECT_FALSE(ServiceNotifier::from_environment().watchdog_timeout());
  EXPECT_TRUE(ServiceNotifier::from_environment().active());
  ::unsetenv("NOTIFY_SOCKET");
  EXPECT_FALSE(ServiceNotifier::from_environment().active());
  ::unsetenv("WATCHDOG_USEC");
  ::unsetenv("WATCHDOG_PID");
}

TEST(OutputWatchdog, OnlyARealOutputFeedsIt) {
  const OutputProgress start{.composites = 10, .placeholders = 2};
  // New composites: alive.
  EXPECT_TRUE(output_advanced(start, {.composites = 11, .placeholders = 2}));
  // A render thread stuck with the camera there: the output repeats the
  // last composite (repeats are not counted), nothing new.
  EXPECT_FALSE(output_advanced(start, {.composites = 10, .placeholders = 2}));
  // The camera away: placeholders are the output doing its job.
  EXPECT_TRUE(output_advanced(start, {.composites = 10, .placeholders = 9, .camera_lost = true}));
  // The GPU lost: placeholders for ever; only a restart brings it back.
  EXPECT_FALSE(output_advanced(
      start, {.composites = 10, .placeholders = 9, .camera_lost = true, .renderer_lost = true}));
  EXPECT_FALSE(
      output_advanced(start, {.composites = 10, .placeholders = 9, .renderer_lost = true}));
  // A stuck output thread: nothing moves.
  EXPECT_FALSE(output_advanced(start, start));
}

// The simulated rig under a watchdog of 400 ms: READY=1 once the first
// frame is out, WATCHDOG=1 about every 200 ms while composites come,
// the status line as STATUS=, STOPPING=1 last. Then the same with its
// render thread stuck after 5 frames: the output goes on (the last
// composite again) and so does the status, but the watchdog hears nothing
// more, so systemd would restart the service.
TEST_F(Service, TheRunFeedsTheWatchdogOnlyWhileItsOutputAdvances) {
  const std::string path = (dir_ / "notify").string();
  const NotifySocket systemd(path);
  const ServiceNotifier notifier(path, std::chrono::microseconds(400ms));
  std::FILE *status = std::fopen("/dev/null", "w");
  ASSERT_NE(status, nullptr);
  const auto run = [&](std::optional<std::uint64_t> stall) {
    RunOptions options;
    options.board = load_board(resolve_board("sim"));
    options.outputs = {"null"};
    options.duration_s = 3.0;
    options.status = status;
    options.service = &notifier;
    options.stall_render_after_frames = stall;
    // Read as systemd does, while the run goes: a datagram socket's queue
    // is short (net.unix.max_dgram_qlen, 10 by default).
    std::vector<std::string> messages;
    std::thread reader([&] { messages = systemd.until_stopping(); });
    (void)run_pipeline(options);
    reader.join();
    int watchdogs = 0, late_watchdogs = 0, statuses = 0;
    for (const std::string &m : messages) {
      watchdogs += m == "WATCHDOG=1" ? 1 : 0;
      statuses += m.rfind("STATUS=in ", 0) == 0 ? 1 : 0;
    }
    // Where the watchdog messages fall among the statuses (one a second):
    // after the second status, the run has been going for 2 s.
    int seen_status = 0;
    for (const std::string &m : messages) {
      seen_status += m.rfind("STATUS=", 0) == 0 ? 1 : 0;
      late_watchdogs += seen_status >= 2 && m == "WATCHDOG=1" ? 1 : 0;
    }
    EXPECT_FALSE(messages.empty());
    if (!messages.empty()) {
      EXPECT_EQ(messages.front(), "READY=1");
      EXPECT_EQ(messages.back(), "STOPPING=1");
    }
    EXPECT_GE(statuses, 2);
    std::printf("%s: %zu messages, %d statuses, %d WATCHDOG=1 (%d after the second status)\n",
                stall ? "render stuck after 5 frames" : "running", messages.size(), statuses,
                watchdogs, late_watchdogs);
    return std::pair(watchdogs, late_watchdogs);
  };
  const auto [running, running_late] = run(std::nullopt);
  EXPECT_GE(running, 8) << "about every 200 ms for 3 s";
  EXPECT_GE(running_late, 3);
  const auto [stuck, stuck_late] = run(5);
  EXPECT_EQ(stuck_late, 0) << "a stuck render thread still fed the watchdog";
  std::fclose(status);
}

} // namespace
} // namespace camhead::pipeline
