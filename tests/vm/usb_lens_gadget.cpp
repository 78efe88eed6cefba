// The USB lens-encoder board (docs/usb-lens-protocol.md) played by Linux
// FunctionFS, for the hardware lab: given a mounted FunctionFS instance, it
// writes the protocol's descriptors and strings to ep0, and once the host has
// configured the gadget (ENABLE) streams reports on the interrupt IN endpoint
// (ep1) at a fixed rate, counts following LensRamp, the index restarting at
// every connection as a bus-powered board's would. It answers GET_INFO and
// stalls every other vendor request.
//
//   camhead_usb_lens_gadget --ffs DIR [--rate HZ] [--count N] [--corrupt-at K]...
//                           [--clock-start-us US] [--firmware X.Y.Z] [--done-file FILE]
//
//   --count N       reports per connection, then quiet until the host goes
//                   away (0: no limit). After the N-th report "done C N" (C the
//                   connection, from 1) is appended to --done-file, so that a
//                   script can unplug (unbind the UDC) and replug (rebind).
//   --corrupt-at K  in the first connection, send report K with one bit
//                   flipped after its CRC (repeatable).
//   --clock-start-us  the device clock at each connection's start; the
//                   default wraps the 32-bit clock 0.5 s into the stream.
//
// Runs until killed. usb_lens.sh makes the configfs gadget around it.
//
// Threads: the ep0 thread reads FunctionFS events (ENABLE, DISABLE, SETUP,
// ...) and answers control requests; the main thread streams. They share one
// mutex-guarded state. ep1 is opened O_NONBLOCK so that a write while the
// function is disabled fails at once (EAGAIN) instead of waiting for the next
// connection and sending it a stale report.
#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <mutex>
#include <set>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <endian.h>
#include <fcntl.h>
#include <linux/usb/ch9.h>
#include <linux/usb/functionfs.h>
#include <unistd.h>

#include "camhead/hal/lens/usb/lens_ramp.h"
#include "camhead/hal/lens/usb/usb_lens_descriptors.h"
#include "camhead/hal/lens/usb/usb_lens_protocol.h"

namespace {

using namespace camhead::hal::lens;

struct Options {
  std::string ffs;
  double rate_hz = 200.0;
  std::uint64_t count = 0;
  std::set<std::uint64_t> corrupt_at;
  std::uint32_t clock_start_us = 0xFFFFFFFFu - 500'000;
  std::uint32_t firmware = 0x010000;
  std::string done_file;
};

void log(const std::string &text) {
  std::fprintf(stderr, "usb_lens_gadget: %s\n", text.c_str());
}

[[noreturn]] void die(const std::string &text) {
  log(text);
  std::exit(1);
}

[[noreturn]] void usage(const std::string &problem) {
  die(problem + "\nusage: camhead_usb_lens_gadget --ffs DIR [--rate HZ] [--count N] "
                "[--corrupt-at K]... [--clock-start-us US] [--firmware X.Y.Z] [--done-file FILE]");
}

std::uint64_t parse_number(const std::string &option, const char *text) {
  char *end = nullptr;
  errno = 0;
  const unsigned long long value = std::strtoull(text, &end, 0);
  if (errno != 0 || end == text || *end != '\0') {
    usage(option + ": \"" + text + "\" is not a number");
  }
  return value;
}

Options parse_options(int argc, char **argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    if (i + 1 >= argc) {
      usage(option + " needs a value");
    }
    const char *value = argv[++i];
    if (option == "--ffs") {
      o.ffs = value;
    } else if (option == "--rate") {
      o.rate_hz = static_cast<double>(parse_number(option, value));
    } else if (option == "--count") {
      o.count = parse_number(option, value);
    } else if (option == "--corrupt-at") {
      o.corrupt_at.insert(parse_number(option, value));
    } else if (option == "--clock-start-us") {
      o.clock_start_us = static_cast<std::uint32_t>(parse_number(option, value));
    } else if (option == "--firmware") {
      unsigned major = 0, minor = 0, patch = 0;
      if (std::sscanf(value, "%u.%u.%u", &major, &minor, &patch) != 3) {
        usage("--firmware: \"" + std::string(value) + "\" is not X.Y.Z");
      }
      o.firmware = (major << 16) | ((minor & 0xFF) << 8) | (patch & 0xFF);
    } else if (option == "--done-file") {
      o.done_file = value;
    } else {
      usage("unknown option " + option);
    }
  }
  if (o.ffs.empty()) {
    usage("--ffs is required");
  }
  if (o.rate_hz < 1.0 || o.rate_hz > 1000.0) {
    usage("--rate: 1 to 1000 Hz (the endpoint is polled every 1 ms)");
  }
  return o;
}

// An owned file descriptor.
class Fd {
public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) {
      ::close(fd_);
    }
  }
  Fd(const Fd &) = delete;
  Fd &operator=(const Fd &) = delete;
  [[nodiscard]] int get() const { return fd_; }

private:
  int fd_;
};

std::int64_t monotonic_us() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000 + ts.tv_nsec / 1000;
}

void sleep_until_us(std::int64_t t_us) {
  timespec ts{static_cast<time_t>(t_us / 1'000'000), static_cast<long>((t_us % 1'000'000) * 1000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

// What the ep0 thread learns and the streaming thread acts on.
struct Bus {
  std::mutex mutex;
  std::condition_variable changed;
  bool enabled = false;
  std::uint64_t enables = 0;                // ENABLE events so far: one per connection
  std::atomic<std::int64_t> power_up_us{0}; // this connection's start, for GET_INFO
};

std::uint32_t device_time_us(const Options &o, std::int64_t power_up_us, std::int64_t now_us) {
  // Modulo 2^32, as the board's free-running counter.
  return o.clock_start_us + static_cast<std::uint32_t>(now_us - power_up_us);
}

void answer_setup(int ep0, const usb_ctrlrequest &setup, const Options &o, const Bus &bus) {
  const std::uint16_t length = le16toh(setup.wLength);
  if (setup.bRequestType == kUsbLensGetInfoRequestType &&
      setup.bRequest == kUsbLensGetInfoRequest) {
    BoardInfo info;
    info.axes = kAxesAll;
    info.firmware_version = o.firmware;
    info.device_time_us = device_time_us(o, bus.power_up_us.load(), monotonic_us());
    info.report_rate_hz = static_cast<std::uint16_t>(o.rate_hz);
    const auto bytes = encode_board_info(info);
    const std::size_t n = std::min<std::size_t>(bytes.size(), length);
    if (::write(ep0, bytes.data(), n) < 0) {
      log(std::string{"ep0: GET_INFO data stage: "} + std::strerror(errno));
    }
    return;
  }
  // FunctionFS: a read on an IN request, or a write on an OUT one, stalls.
  log("ep0: stalling request type " + std::to_string(setup.bRequestType) + " request " +
      std::to_string(setup.bRequest));
  const ssize_t ignored =
      (setup.bRequestType & USB_DIR_IN) != 0 ? ::read(ep0, nullptr, 0) : ::write(ep0, nullptr, 0);
  (void)ignored;
}

void serve_ep0(int ep0, const Options &o, Bus &bus) {
  std::array<usb_functionfs_event, 4> events{};
  for (;;) {
    const ssize_t n = ::read(ep0, events.data(), sizeof events);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) {
        continue;
      }
      die(std::string{"ep0: read events: "} + std::strerror(errno));
    }
    // A SETUP event is always the last of a batch: its data stage comes next.
    for (std::size_t i = 0; i < static_cast<std::size_t>(n) / sizeof(usb_functionfs_event); ++i) {
      switch (events[i].type) {
      case FUNCTIONFS_ENABLE: {
        log("ENABLE");
        std::lock_guard lock(bus.mutex);
        bus.enabled = true;
        ++bus.enables;
        bus.changed.notify_all();
        break;
      }
      case FUNCTIONFS_DISABLE:
      case FUNCTIONFS_UNBIND: {
        log(events[i].type == FUNCTIONFS_DISABLE ? "DISABLE" : "UNBIND");
        std::lock_guard lock(bus.mutex);
        bus.enabled = false;
        bus.changed.notify_all();
        break;
      }
      case FUNCTIONFS_SETUP:
        answer_setup(ep0, events[i].u.setup, o, bus);
        break;
      default: // BIND, SUSPEND, RESUME: nothing to do
        break;
      }
    }
  }
}

void append_done(const Options &o, std::uint64_t connection, std::uint64_t sent) {
  if (o.done_file.empty()) {
    return;
  }
  if (FILE *f = std::fopen(o.done_file.c_str(), "a")) {
    std::fprintf(f, "done %llu %llu\n", static_cast<unsigned long long>(connection),
                 static_cast<unsigned long long>(sent));
    std::fclose(f);
  } else {
    log("cannot append to " + o.done_file + ": " + std::strerror(errno));
  }
}

// One connection: reports 0, 1, ... at the rate until --count, a disconnect
// or an error. Returns how many went out.
std::uint64_t stream(int ep1, const Options &o, Bus &bus, std::uint64_t connection) {
  const auto period_us = static_cast<std::int64_t>(1e6 / o.rate_hz);
  const std::int64_t power_up = monotonic_us();
  bus.power_up_us = power_up;
  const LensRamp ramp;
  std::int64_t next_us = power_up;
  std::uint64_t sent = 0;
  for (std::uint64_t k = 0; o.count == 0 || k < o.count; ++k) {
    sleep_until_us(next_us);
    {
      std::lock_guard lock(bus.mutex);
      if (!bus.enabled) {
        break;
      }
    }
    const LensAxes axes = ramp.at(static_cast<std::uint32_t>(k));
    LensReport report;
    report.sequence = static_cast<std::uint32_t>(k);
    report.device_time_us = device_time_us(o, power_up, monotonic_us()); // latched now
    report.focus = axes.focus;
    report.iris = axes.iris;
    report.zoom = axes.zoom;
    auto bytes = encode_report(report);
    if (connection == 1 && o.corrupt_at.count(k) != 0) {
      bytes[12] ^= 0x01; // focus LSB, after the CRC was computed
      log("report " + std::to_string(k) + " sent corrupted");
    }
    // Blocks until the host has read it: nothing is lost while the host is
    // still opening the board, and the pace follows the host's polling.
    const ssize_t w = ::write(ep1, bytes.data(), bytes.size());
    if (w != static_cast<ssize_t>(bytes.size())) {
      log("connection " + std::to_string(connection) + " ended after " + std::to_string(sent) +
          " reports: " + (w < 0 ? std::strerror(errno) : "short write"));
      break;
    }
    ++sent;
    // An absolute schedule, restarted when the host held a report longer
    // than a period: catching up in a burst would not be a 200 Hz board.
    next_us = std::max(next_us + period_us, monotonic_us());
  }
  return sent;
}

} // namespace

int main(int argc, char **argv) {
  const Options o = parse_options(argc, argv);
  const std::string ep0_path = o.ffs + "/ep0";
  const Fd ep0(::open(ep0_path.c_str(), O_RDWR));
  if (ep0.get() < 0) {
    die("cannot open " + ep0_path + ": " + std::strerror(errno));
  }
  const std::vector<std::uint8_t> descriptors = functionfs_descriptors();
  const std::vector<std::uint8_t> strings = functionfs_strings();
  if (::write(ep0.get(), descriptors.data(), descriptors.size()) !=
      static_cast<ssize_t>(descriptors.size())) {
    die(ep0_path + ": writing descriptors: " + std::strerror(errno));
  }
  if (::write(ep0.get(), strings.data(), strings.size()) != static_cast<ssize_t>(strings.size())) {
    die(ep0_path + ": writing strings: " + std::strerror(errno));
  }
  const std::string ep1_path = o.ffs + "/ep1";
  const Fd ep1(::open(ep1_path.c_str(), O_RDWR | O_NONBLOCK));
  if (ep1.get() < 0) {
    die("cannot open " + ep1_path + ": " + std::strerror(errno));
  }
  log("descriptors written; " + std::to_string(static_cast<int>(o.rate_hz)) + " Hz, " +
      (o.count == 0 ? std::string{"no limit"} : std::to_string(o.count) + " reports") +
      " per connection");

  Bus bus;
  std::thread(serve_ep0, ep0.get(), std::cref(o), std::ref(bus)).detach();

  std::uint64_t seen = 0;
  for (std::uint64_t connection = 1;; ++connection) {
    {
      std::unique_lock lock(bus.mutex);
      bus.changed.wait(lock, [&] { return bus.enabled && bus.enables > seen; });
      seen = bus.enables;
    }
    const std::uint64_t sent = stream(ep1.get(), o, bus, connection);
    if (o.count != 0 && sent == o.count) {
      log("connection " + std::to_string(connection) + ": " + std::to_string(sent) +
          " reports sent");
      append_done(o, connection, sent);
    }
    // Quiet until the host goes away; the next ENABLE is a new connection.
    std::unique_lock lock(bus.mutex);
    bus.changed.wait(lock, [&] { return !bus.enabled || bus.enables > seen; });
  }
}
