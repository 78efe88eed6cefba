// Hardware-lab check of the DRM/KMS sink on QEMU's standard VGA (bochs-drm,
// one connector, Virtual-1, 1280x800 preferred). What is on screen is read
// on the host: this program asks over the lab's control port (/dev/ttyS1)
// for a QEMU monitor screendump and a verdict on it, which screen_helper.py
// gives (it knows the test pattern below), and prints that verdict as its
// RESULT line. A second descriptor on the card (the observer, not master)
// reads the CRTC state, and keeps the card open so that the kernel's own
// restore of the text console on last close cannot stand in for the sink's.
//
//   drm_master_busy          open fails, naming the card, while another
//                            descriptor is DRM master
//   drm_frame_too_large      a 1920x1080 frame in a 1280x800 mode is refused,
//                            naming both
//   drm_open                 open by driver name at 640x480 in mode 1280x800
//   drm_placeholder          before any frame: mid-grey (128) in the frame
//                            area, black borders (screendump)
//   drm_frame                the first frame exact, centred (screendump)
//   drm_flip                 a dozen frames through the page-flip cycle, the
//                            last one exact on screen (screendump)
//   drm_close_restores_crtc  after close(): the CRTC shows the framebuffer,
//                            mode and position it had before
//   drm_console_back         ... and the screen is the text console again,
//                            pixel for pixel as before open (screendump)
//   drm_full_frame           a 1280x800 frame in the 1280x800 mode, at the
//                            dumb buffer's pitch, is copied into it whole
//                            (screendump)
//   drm_destructor_restores  a sink destroyed without close() also puts the
//                            console back
//   drm_card_back            the card unplugged and back (PCI remove and
//                            rescan), 100 times (10 under the sanitizers):
//                            frames skipped and said while it is away, and
//                            going out again once it is back, each time (by
//                            the driver's name)
//
//   camhead_drm_vm_check CONTROL_TTY
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <drm.h>
#include <drm_mode.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/output/drm/drm_sink.h"
#include "sysfs_attribute.h"
#include "vm_result.h"

namespace {

using camhead::base::PixelFormat;
using camhead::hal::output::DrmSinkError;
using camhead::hal::output::DrmSinkOptions;
using camhead::hal::output::FrameSink;
using camhead::hal::output::open_drm_sink;
using camhead::vm::print_result;
using camhead::vm::write_attribute;

constexpr int kModeWidth = 1280;
constexpr int kModeHeight = 800;
constexpr int kFrameWidth = 640;
constexpr int kFrameHeight = 480;
// Unplugs and replugs of the card (drm_card_back): 100, or 10 in the
// sanitizer build (tests/vm/CMakeLists.txt).
constexpr int kCardCycles = CAMHEAD_LAB_FAULT_CYCLES;

// The test pattern of frame `seed` at pixel (x, y) of the frame; every pixel
// differs from its neighbours in each direction and from the pixel 256 away,
// so a frame misplaced, mis-strided or with red and blue swapped shows.
// screen_helper.py's pattern_row() is the same formula: change both.
struct Rgb {
  std::uint8_t r, g, b;
};
Rgb pattern(int x, int y, int seed) {
  return {static_cast<std::uint8_t>(x * 3 + seed * 50),
          static_cast<std::uint8_t>(y * 5 + seed * 30),
          static_cast<std::uint8_t>(x + y + (x >> 8) * 37 + (y >> 8) * 59 + seed * 70)};
}

// XRGB8888: one little-endian word 0x00RRGGBB per pixel, so bytes B G R X.
void fill(std::span<std::uint8_t> frame, int width, int height, std::size_t stride, int seed) {
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Rgb c = pattern(x, y, seed);
      std::uint8_t *p =
          frame.data() + static_cast<std::size_t>(y) * stride + static_cast<std::size_t>(x) * 4;
      p[0] = c.b;
      p[1] = c.g;
      p[2] = c.r;
      p[3] = 0;
    }
}

// --- The control port to screen_helper.py ---------------------------------------
class Control {
public:
  explicit Control(const char *tty) {
    fd_ = ::open(tty, O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (fd_ < 0)
      return;
    termios raw{};
    if (::tcgetattr(fd_, &raw) == 0) {
      ::cfmakeraw(&raw);
      ::cfsetspeed(&raw, B115200);
      (void)::tcsetattr(fd_, TCSANOW, &raw);
    }
  }
  ~Control() {
    if (fd_ >= 0)
      ::close(fd_);
  }
  Control(const Control &) = delete;
  Control &operator=(const Control &) = delete;

  // Whether the helper answers, asked once a second for `seconds`: bytes sent
  // before it connected to QEMU's socket are lost, so one ask is not enough.
  bool hello(int seconds) {
    for (int k = 0; k < seconds && fd_ >= 0; ++k) {
      const std::string tag = "HELLO " + std::to_string(k);
      if (send(tag) && reply_to(tag, 1000))
        return true;
    }
    return false;
  }

  // A screendump and the helper's verdict: "PASS ..." or "FAIL ...". A
  // submitted frame is on screen once its page flip lands, a vblank or so
  // later, and later still in a sanitizer build on a loaded host (one CI run
  // dumped the placeholder still showing): a FAIL is dumped again, up to 10
  // times 100 ms apart, and the last verdict stands.
  std::string dump(const std::string &name, int width, int height, const std::string &expect) {
    if (!ready_)
      return "SKIP " + why_not_;
    std::string verdict;
    for (int attempt = 0; attempt < 10; ++attempt) {
      if (attempt > 0)
        ::usleep(100'000);
      // Under one name: the helper keeps the last dump of a name for a later
      // "same NAME" verdict, and each attempt waits for its own reply.
      if (!send("DUMP " + name + " " + std::to_string(width) + "x" + std::to_string(height) + " " +
                expect))
        return "FAIL cannot write to the control port: " + std::string(std::strerror(errno));
      const std::optional<std::string> reply = reply_to(name, 60'000);
      if (!reply)
        return "FAIL the screen helper did not answer within 60 s";
      verdict = *reply;
      if (verdict.rfind("FAIL", 0) != 0)
        break;
    }
    return verdict;
  }

  void set_ready(bool ready, std::string why_not) {
    ready_ = ready;
    why_not_ = std::move(why_not);
  }

private:
  bool send(const std::string &line) {
    const std::string bytes = line + "\n";
    return ::write(fd_, bytes.data(), bytes.size()) == static_cast<ssize_t>(bytes.size());
  }

  // The rest of the first line that starts with "TAG ", or "TAG" alone.
  std::optional<std::string> reply_to(const std::string &tag, int timeout_ms) {
    const std::int64_t deadline =
        camhead::base::monotonic_ns() + std::int64_t{timeout_ms} * 1'000'000;
    for (;;) {
      std::size_t end;
      while ((end = pending_.find('\n')) != std::string::npos) {
        std::string line = pending_.substr(0, end);
        pending_.erase(0, end + 1);
        if (!line.empty() && line.back() == '\r')
          line.pop_back();
        if (line == tag)
          return std::string{};
        if (line.starts_with(tag + " "))
          return line.substr(tag.size() + 1);
      }
      const std::int64_t left = (deadline - camhead::base::monotonic_ns()) / 1'000'000;
      if (left <= 0)
        return std::nullopt;
      pollfd ready{fd_, POLLIN, 0};
      if (::poll(&ready, 1, static_cast<int>(left)) <= 0)
        continue;
      char bytes[512];
      const ssize_t n = ::read(fd_, bytes, sizeof bytes);
      if (n > 0)
        pending_.append(bytes, static_cast<std::size_t>(n));
    }
  }

  int fd_ = -1;
  bool ready_ = false;
  std::string why_not_;
  std::string pending_;
};

// A verdict line from the helper as this check's RESULT.
void report(const std::string &name, const std::string &verdict, const std::string &extra = {}) {
  if (verdict.starts_with("SKIP ")) {
    std::printf("RESULT %s: %s\n", name.c_str(), verdict.c_str());
    std::fflush(stdout);
    return;
  }
  const bool pass = verdict.starts_with("PASS");
  const std::string detail = verdict.size() > 5 ? verdict.substr(5) : verdict;
  print_result(name, pass, detail + extra);
}

// --- The observer: a second descriptor on the card ------------------------------
struct Observer {
  int fd = -1;
  std::uint32_t crtc = 0;
  ~Observer() {
    if (fd >= 0)
      ::close(fd);
  }
  template <class Arg> bool ioctl(unsigned long request, Arg &arg) const {
    int result = 0;
    do {
      result = ::ioctl(fd, request, &arg);
    } while (result < 0 && (errno == EINTR || errno == EAGAIN));
    return result == 0;
  }
  std::optional<drm_mode_crtc> state() const {
    drm_mode_crtc crtc_state{};
    crtc_state.crtc_id = crtc;
    if (!ioctl(DRM_IOCTL_MODE_GETCRTC, crtc_state))
      return std::nullopt;
    return crtc_state;
  }
};

std::string describe(const drm_mode_crtc &state) {
  return "fb " + std::to_string(state.fb_id) + ", " +
         (state.mode_valid != 0
              ? std::to_string(state.mode.hdisplay) + "x" + std::to_string(state.mode.vdisplay)
              : std::string("no mode")) +
         " at (" + std::to_string(state.x) + ", " + std::to_string(state.y) + ")";
}

bool same_state(const drm_mode_crtc &a, const drm_mode_crtc &b) {
  return a.fb_id == b.fb_id && a.x == b.x && a.y == b.y && a.mode_valid == b.mode_valid &&
         (a.mode_valid == 0 || std::memcmp(&a.mode, &b.mode, sizeof a.mode) == 0);
}

std::string open_error(const DrmSinkOptions &options) {
  try {
    (void)open_drm_sink(options);
  } catch (const DrmSinkError &e) {
    return e.what();
  }
  return "opened";
}

std::string rect(int width, int height, int x, int y) {
  return std::to_string(width) + "x" + std::to_string(height) + "+" + std::to_string(x) + "+" +
         std::to_string(y);
}

// Sends frame `seed` to the sink; empty when it went out.
std::string send_frame(FrameSink &sink, int seed) {
  const auto format = sink.format();
  std::vector<std::uint8_t> frame(camhead::base::frame_bytes(format));
  fill(frame, format.width, format.height, camhead::base::row_bytes(format), seed);
  if (!sink.submit(frame, camhead::base::monotonic_ns()))
    return "submit failed: " + sink.status().detail;
  return {};
}

// The card unplugged and back `cycles` times: the VGA removed from the PCI
// bus and found again by a rescan, which unbinds bochs and binds it anew
// as an unplug and a replug do (the card comes back under another number
// while the observer holds the old one). While it is away the sink skips
// frames and says so; once it is back it finds the card again by its
// driver's name and frames go out. Last: the screen is not checked after.
void card_unplugged(int cycles) {
  char device[4096] = {};
  if (::realpath("/sys/class/drm/card0/device", device) == nullptr) {
    print_result("drm_card_back", false, "no /sys/class/drm/card0/device");
    return;
  }
  std::unique_ptr<FrameSink> sink;
  try {
    sink = open_drm_sink(DrmSinkOptions{"bochs-drm", "", kFrameWidth, kFrameHeight, "1280x800"});
  } catch (const std::exception &e) {
    print_result("drm_card_back", false, e.what());
    return;
  }
  const auto format = sink->format();
  std::vector<std::uint8_t> frame(camhead::base::frame_bytes(format));
  fill(frame, format.width, format.height, camhead::base::row_bytes(format), 4);
  std::vector<double> back_ms;
  std::string problem, gone_detail;
  for (int cycle = 0; cycle < cycles && problem.empty(); ++cycle) {
    if (!sink->submit(frame, 0)) {
      problem = "cycle " + std::to_string(cycle) +
                ": no frame before the unplug: " + sink->status().detail;
      break;
    }
    try {
      write_attribute(std::string(device) + "/remove", "1");
    } catch (const std::exception &e) {
      problem = e.what();
      break;
    }
    // Frames at 25 a second while it is away: skipped, and said.
    bool seen_gone = false;
    for (int k = 0; k < 25 && !seen_gone; ++k) {
      seen_gone = !sink->submit(frame, 0) && !sink->status().connected;
      ::usleep(40'000);
    }
    gone_detail = sink->status().detail;
    if (!seen_gone) {
      problem =
          "cycle " + std::to_string(cycle) + ": the sink did not see the card go: " + gone_detail;
      break;
    }
    try {
      write_attribute("/sys/bus/pci/rescan", "1");
    } catch (const std::exception &e) {
      problem = e.what();
      break;
    }
    const std::int64_t rescanned = camhead::base::monotonic_ns();
    bool back = false;
    while (!back && camhead::base::monotonic_ns() - rescanned < 10'000'000'000) {
      back = sink->submit(frame, 0);
      if (!back)
        ::usleep(40'000);
    }
    if (!back) {
      problem = "cycle " + std::to_string(cycle) +
                ": not back 10 s after the rescan: " + sink->status().detail;
      break;
    }
    back_ms.push_back(double(camhead::base::monotonic_ns() - rescanned) * 1e-6);
  }
  std::string detail = problem;
  if (!back_ms.empty()) {
    detail += (detail.empty() ? "" : "; ") + std::to_string(back_ms.size()) + " of " +
              std::to_string(cycles) + " back, " + camhead::vm::median_and_worst_ms(back_ms) +
              " after the rescan; while away: " + gone_detail + "; back: " + sink->status().detail;
  }
  print_result("drm_card_back", problem.empty() && int(back_ms.size()) == cycles, detail);
}

} // namespace

int main(int argc, char **argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: camhead_drm_vm_check CONTROL_TTY\n");
    return 2;
  }
  Control control(argv[1]);
  if (control.hello(10))
    control.set_ready(true, {});
  else
    control.set_ready(false, "no screen helper answered on " + std::string(argv[1]) +
                                 " (run_lab.sh starts it where python3 is installed)");

  Observer observer;
  observer.fd = ::open("/dev/dri/card0", O_RDWR | O_CLOEXEC);
  drm_mode_card_res res{};
  std::uint32_t crtcs[4] = {};
  res.crtc_id_ptr = reinterpret_cast<std::uintptr_t>(crtcs);
  res.count_crtcs = 4;
  if (observer.fd < 0 || !observer.ioctl(DRM_IOCTL_MODE_GETRESOURCES, res) || res.count_crtcs < 1) {
    std::printf("LAB drm: cannot read /dev/dri/card0's CRTCs: %s\n", std::strerror(errno));
    return 1;
  }
  observer.crtc = crtcs[0]; // bochs has one

  // Another master: the observer is one while it holds master.
  int unused = 0;
  if (observer.ioctl(DRM_IOCTL_SET_MASTER, unused)) {
    DrmSinkOptions busy{"bochs-drm", "", kFrameWidth, kFrameHeight, ""};
    const std::string error = open_error(busy);
    print_result("drm_master_busy",
                 error.find("card0 (bochs-drm): another program is DRM master") == 0, error);
  } else {
    print_result("drm_master_busy", false,
                 "the observer could not become master: " + std::string(std::strerror(errno)));
  }
  if (!observer.ioctl(DRM_IOCTL_DROP_MASTER, unused)) {
    std::printf("LAB drm: the observer cannot drop master: %s\n", std::strerror(errno));
    return 1;
  }

  {
    DrmSinkOptions large{"card0", "", 1920, 1080, "1280x800"};
    const std::string error = open_error(large);
    print_result("drm_frame_too_large",
                 error.find("card0 (bochs-drm): connector Virtual-1") == 0 &&
                     error.find("1920x1080") != std::string::npos &&
                     error.find("1280x800") != std::string::npos,
                 error);
  }

  const std::optional<drm_mode_crtc> before = observer.state();
  if (!before) {
    std::printf("LAB drm: GETCRTC: %s\n", std::strerror(errno));
    return 1;
  }
  std::printf("LAB drm: before the sink the CRTC shows %s\n", describe(*before).c_str());
  const int console_width = before->mode_valid ? before->mode.hdisplay : kModeWidth;
  const int console_height = before->mode_valid ? before->mode.vdisplay : kModeHeight;
  const std::string console_before =
      control.dump("console_before", console_width, console_height, "console");

  // The sink by driver name, first connected connector, mode as asked.
  std::unique_ptr<FrameSink> sink;
  try {
    sink = open_drm_sink(DrmSinkOptions{"bochs-drm", "", kFrameWidth, kFrameHeight, "1280x800"});
  } catch (const std::exception &e) {
    print_result("drm_open", false, e.what());
    return 1;
  }
  const auto format = sink->format();
  const bool format_ok = format.pixel == PixelFormat::xrgb8888 && format.width == kFrameWidth &&
                         format.height == kFrameHeight && format.stride == 0;
  print_result("drm_open", format_ok && sink->status().connected,
               sink->status().detail + " [format " + camhead::base::describe(format) + "]");

  const int x0 = (kModeWidth - kFrameWidth) / 2, y0 = (kModeHeight - kFrameHeight) / 2;
  const std::string area = rect(kFrameWidth, kFrameHeight, x0, y0);
  report("drm_placeholder",
         control.dump("placeholder", kModeWidth, kModeHeight, "grey " + area + " 128"));

  if (const std::string problem = send_frame(*sink, 1); !problem.empty())
    print_result("drm_frame", false, problem);
  else
    report("drm_frame", control.dump("frame", kModeWidth, kModeHeight, "pattern " + area + " 1"));

  // Frames 10..20, then 2: each waits in submit() for the last one's flip.
  std::string problem;
  const std::int64_t start = camhead::base::monotonic_ns();
  for (int seed = 10; seed <= 21 && problem.empty(); ++seed)
    problem = send_frame(*sink, seed == 21 ? 2 : seed);
  const double ms_per_frame = (camhead::base::monotonic_ns() - start) / 12.0 / 1e6;
  const auto status = sink->status();
  if (problem.empty() && (status.frames != 13 || status.errors != 0))
    problem = std::to_string(status.frames) + " frames, " + std::to_string(status.errors) +
              " errors after 13 submits: " + status.detail;
  if (!problem.empty())
    print_result("drm_flip", false, problem);
  else
    report("drm_flip", control.dump("flip", kModeWidth, kModeHeight, "pattern " + area + " 2"),
           "; 12 frames at " + std::to_string(ms_per_frame) + " ms each; " + status.detail);

  const bool closed = sink->close();
  const std::optional<drm_mode_crtc> after = observer.state();
  print_result("drm_close_restores_crtc", closed && after && same_state(*before, *after),
               sink->status().detail + "; CRTC before: " + describe(*before) +
                   ", after: " + (after ? describe(*after) : std::string("unreadable")));
  sink.reset();
  const std::string console_after =
      control.dump("console_after", console_width, console_height, "same console_before");
  if (console_before.starts_with("FAIL"))
    report("drm_console_back", console_before, " (the console before open)");
  else
    report("drm_console_back", console_after);

  // Frame and mode the same size: the frame at the buffer's pitch, by path and
  // connector name.
  try {
    auto full = open_drm_sink(
        DrmSinkOptions{"/dev/dri/card0", "Virtual-1", kModeWidth, kModeHeight, "1280x800@75"});
    const auto f = full->format();
    const std::string stride = "stride " + std::to_string(f.stride);
    if (f.stride < kModeWidth * 4)
      print_result("drm_full_frame", false, stride + " is not the dumb buffer's pitch");
    else if (const std::string trouble = send_frame(*full, 3); !trouble.empty())
      print_result("drm_full_frame", false, trouble);
    else
      report("drm_full_frame",
             control.dump("full_frame", kModeWidth, kModeHeight,
                          "pattern " + rect(kModeWidth, kModeHeight, 0, 0) + " 3"),
             "; " + stride + "; " + full->status().detail);
    full.reset(); // no close(): the destructor restores
    const std::optional<drm_mode_crtc> left = observer.state();
    print_result("drm_destructor_restores", left && same_state(*before, *left),
                 "CRTC before: " + describe(*before) +
                     ", after the destructor: " + (left ? describe(*left) : "unreadable"));
  } catch (const std::exception &e) {
    print_result("drm_full_frame", false, e.what());
    print_result("drm_destructor_restores", false, "not run: the sink did not open");
  }
  card_unplugged(kCardCycles);
  return 0;
}
