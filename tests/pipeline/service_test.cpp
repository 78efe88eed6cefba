// `camhead run` as a systemd service (service/service_notifier.h,
// service/output_watchdog.h): the notify protocol against a socket the test
// owns, as systemd's is, and the watchdog that only a really advancing
// output feeds.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <sys/socket.h>
#include <sys/uio.h>
#include <sys/un.h>
#include <unistd.h>

#include "camhead/base/monotonic_clock.h"
#include "camhead/base/realtime_stamp.h"
#include "camhead/renderer/gpu_tracer.h"
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

  // The next message and when it was sent (CLOCK_MONOTONIC): the kernel
  // stamps each datagram as the sender hands it over (SO_TIMESTAMPNS), so a
  // reader that a loaded machine wakes late still sees when it came.
  std::optional<std::pair<std::string, std::int64_t>>
  receive_stamped(std::chrono::milliseconds timeout) const {
    const int on = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
    timeval tv{long(timeout.count() / 1000), long(timeout.count() % 1000) * 1000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    char buffer[4096];
    iovec io{buffer, sizeof buffer};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
    msghdr message{};
    message.msg_iov = &io;
    message.msg_iovlen = 1;
    message.msg_control = control;
    message.msg_controllen = sizeof control;
    const ssize_t n = ::recvmsg(fd_, &message, 0);
    if (n < 0)
      return std::nullopt;
    // When it was sent: the kernel's realtime stamp, on the monotonic clock.
    const base::ClockPair now = base::read_clock_pair();
    std::int64_t sent_ns = now.monotonic_ns;
    for (cmsghdr *c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c))
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
        timespec stamp{};
        std::memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
        sent_ns = base::receipt_ns(std::int64_t(stamp.tv_sec) * 1'000'000'000 + stamp.tv_nsec, now,
                                   std::numeric_limits<std::int64_t>::min(), now.monotonic_ns);
      }
    return std::pair(std::string(buffer, std::size_t(n)), sent_ns);
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

// systemd drains its socket; one that does not (stopped, or slow) must
// not hold up the status thread: once the socket's queue is full the
// messages are lost, at once, never waited for.
TEST_F(Service, AFullSocketLosesMessagesWithoutWaiting) {
  const std::string path = (dir_ / "notify").string();
  const NotifySocket never_read(path);
  const ServiceNotifier notifier(path);
  int sent = 0, lost = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 1000; ++i)
    (notifier.notify("STATUS=in 25.0 fps") ? sent : lost) += 1;
  const auto took = std::chrono::steady_clock::now() - start;
  std::printf("%d sent, %d lost in %.1f ms\n", sent, lost,
              std::chrono::duration<double, std::milli>(took).count());
  EXPECT_GT(sent, 0);
  EXPECT_GT(lost, 0) << "the socket's queue never filled";
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

// The simulated rig under a watchdog of 400 ms (a check every 200 ms):
// READY=1 once the first frame is out, the status line as STATUS=,
// STOPPING=1 last, and WATCHDOG=1 only where a composite went out in the
// check's window. Then the render thread stuck after 2 frames (the output
// goes on with the last composite again), and the GPU lost after 2 frames
// (the output goes on with the placeholder): the status goes on too, but
// the watchdog hears nothing once the last composite is a window old, so
// systemd would restart the service. Judged against the run's own record
// of when each composite went out, whatever the machine's rate (a
// sanitizer build renders far slower).
TEST_F(Service, TheRunFeedsTheWatchdogOnlyWhileItsOutputAdvances) {
  if (renderer::list_gpu_devices().empty())
    GTEST_SKIP() << "no Vulkan device";
  const std::string path = (dir_ / "notify").string();
  const NotifySocket systemd(path);
  constexpr std::int64_t kWindowNs = 200'000'000; // half the timeout
  constexpr std::int64_t kSlackNs = 100'000'000;  // the status thread's 20-ms naps, scheduling
  const ServiceNotifier notifier(path, std::chrono::microseconds(2 * kWindowNs / 1000));
  std::FILE *status = std::fopen("/dev/null", "w");
  ASSERT_NE(status, nullptr);
  struct Message {
    std::string text;
    std::int64_t at_ns;
  };
  enum class Fault { none, render_stuck, gpu_lost };
  // Runs for `seconds`, or until `frames` composites went out if sooner.
  const auto run = [&](Fault fault, double seconds, std::uint64_t frames) {
    RunOptions options;
    options.board = load_board(resolve_board("sim"));
    // No cache, so no warm-up before the first frame (rig_setup.h): what
    // is judged is the run's watchdog, from its first frame.
    std::get<SimCameraConfig>(options.board.camera->kind).cache_mb = 0;
    options.outputs = {"null"};
    options.duration_s = seconds;
    options.frames = frames;
    options.status = status;
    options.service = &notifier;
    options.stats_file = dir_ / "stats.jsonl";
    if (fault == Fault::render_stuck)
      options.stall_render_after_frames = 2;
    if (fault == Fault::gpu_lost)
      options.lose_gpu_after_frames = 2;
    // Vulkan (lavapipe here): frames at the camera's rate in a sanitizer
    // build too, whose CPU reference renders a frame or two a second.
    options.executor = Executor::gpu;
    // Read as systemd does, while the run goes: a datagram socket's queue
    // is short (net.unix.max_dgram_qlen, 10 by default).
    std::vector<Message> messages;
    std::thread reader([&] {
      while (auto m = systemd.receive_stamped(5000ms)) {
        messages.push_back({m->first, m->second});
        if (m->first == "STOPPING=1")
          break;
      }
    });
    (void)run_pipeline(options);
    reader.join();
    std::vector<std::int64_t> composites_out;
    int placeholders_after = 0; // after the last composite
    std::ifstream stats(dir_ / "stats.jsonl");
    for (std::string line; std::getline(stats, line);) {
      if (line.find("\"kind\":\"composite\"") != std::string::npos) {
        composites_out.push_back(std::int64_t(json_number(line, "output_ns")));
        placeholders_after = 0;
      }
      placeholders_after += line.find("\"kind\":\"placeholder\"") != std::string::npos ? 1 : 0;
    }
    // The outputs go on with the placeholder (a filler every 0.5 s of
    // silence, run_loop.h's repeat_after_s).
    if (fault == Fault::gpu_lost) {
      EXPECT_GE(placeholders_after, 2) << "placeholders after the last composite";
    }
    EXPECT_FALSE(composites_out.empty());
    EXPECT_FALSE(messages.empty());
    if (messages.empty() || composites_out.empty())
      return std::pair(0, std::int64_t(0));
    EXPECT_EQ(messages.front().text, "READY=1");
    EXPECT_EQ(messages.back().text, "STOPPING=1");
    int watchdogs = 0, statuses = 0;
    std::int64_t last_status_ns = 0;
    for (const Message &m : messages) {
      if (m.text.rfind("STATUS=in ", 0) == 0) {
        ++statuses;
        last_status_ns = m.at_ns;
      }
      if (m.text != "WATCHDOG=1")
        continue;
      ++watchdogs;
      // A composite went out in the window this ping closes.
      const bool earned = std::any_of(composites_out.begin(), composites_out.end(), [&](auto t) {
        return t <= m.at_ns && t > m.at_ns - kWindowNs - kSlackNs;
      });
      EXPECT_TRUE(earned) << "WATCHDOG=1 with no composite in the 300 ms before it";
    }
    // The status goes on while the output has stopped (a healthy run is
    // too short to judge it: it ends on its frames).
    if (fault != Fault::none) {
      EXPECT_GE(statuses, 2);
    }
    std::printf("%s: %zu composites, %zu messages, %d statuses, %d WATCHDOG=1\n",
                fault == Fault::render_stuck ? "render stuck after 2 frames"
                : fault == Fault::gpu_lost   ? "the GPU lost after 2 frames"
                                             : "running",
                composites_out.size(), messages.size(), statuses, watchdogs);
    // How long the run went on after its last composite, for the stall.
    return std::pair(watchdogs, last_status_ns - composites_out.back());
  };
  // A healthy run ends on its frames, not the clock: on a loaded machine a
  // sanitizer build's first frames take seconds (2 composites in 3 s once,
  // and so no WATCHDOG=1 to judge). Ten composites close at least one
  // 200-ms window before the last.
  const auto [running, running_tail] = run(Fault::none, 60.0, 10);
  EXPECT_GE(running, 1);
  // Long enough for the fault to be judged on a loaded machine, where the
  // first frames take seconds (a sanitizer suite beside it: 3 composites
  // in the first 3 s).
  for (const Fault fault : {Fault::render_stuck, Fault::gpu_lost}) {
    const auto [faulted, faulted_tail] = run(fault, 6.0, 0);
    // The run went on for more than a window after its last composite (the
    // status kept coming, and with the GPU lost the placeholder too), so a
    // watchdog fed by a live main thread or a moving output alone would
    // have been pinged meanwhile: the check in run() says it was not.
    EXPECT_GT(faulted_tail, 2 * kWindowNs) << "the fault came too late in the run to be judged";
    (void)faulted;
  }
  (void)running_tail;
  std::fclose(status);
}

} // namespace
} // namespace camhead::pipeline
