// Hardware-lab check: the USB lens board unplugged and plugged back again
// and again, by unbinding and binding the gadget's UDC, with the lens read
// through open_usb_lens() alone: the backend's own recovery and its times,
// without the pipeline around it (usb_run_check.cpp runs `camhead run`
// through the 100 plugs of issue 26's fault loop). Prints one RESULT line:
//
//   usb_replug_backend  10 times in a row: the lens says it is gone (stale)
//                   after the unplug, and readings come again after the
//                   plug, each within 500 ms of the kernel having the board
//                   enumerated again (its serial in /sys/bus/usb/devices);
//                   the median and worst of that, and of the plug to the
//                   first reading (which adds the emulated bus's
//                   enumeration, about half a second)
//
// Under the sanitizers (CAMHEAD_LAB_SANITIZED) the 500 ms is reported, not
// held, as usb_run_check.cpp does: the instrumented backend in the one-CPU
// emulated guest beside a loaded host took 503 and 519 ms for its first
// plug in two of three sanitizer suites (2026-12-06), 289 ms median in the
// third. The release lab holds it; the states and the reconnect count hold
// in both.
//
//   camhead_usb_replug_check UDC_ATTRIBUTE UDC SERIAL
//
// Run by usb_lens.sh with the gadget bound and its program (usb_lens_gadget)
// streaming a burst of reports on every connection.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/lens/usb/usb_lens.h"
#include "sysfs_attribute.h"
#include "vm_result.h"

namespace {

using namespace camhead::hal::lens;
using camhead::base::monotonic_ns;
using namespace std::chrono_literals;

constexpr int kReplugs = 10;
constexpr std::int64_t kGiveUpNs = 10'000'000'000;
constexpr double kBackWithinMs = 500.0;
constexpr bool kTimed = CAMHEAD_LAB_SANITIZED == 0;

struct Back {
  double plug_ms = 0;       // the plug to the first reading
  double enumerated_ms = 0; // the enumeration to the first reading
};

// Polls the lens until `done` says so or 10 s pass; false on the timeout.
template <typename Done> bool poll_until(LensEncoder &lens, Done done) {
  const std::int64_t give_up = monotonic_ns() + kGiveUpNs;
  std::vector<EncoderReading> out;
  while (monotonic_ns() < give_up) {
    out.clear();
    lens.poll(5ms, out);
    if (done(out))
      return true;
  }
  return false;
}

std::string replug(const std::string &udc_file, const std::string &udc, const std::string &serial,
                   LensEncoder &lens, int times, std::vector<Back> &back) {
  // Connected, to begin with (this connection's burst may be over).
  if (!poll_until(lens,
                  [&](const std::vector<EncoderReading> &) { return lens.status().connected; }))
    return "not connected before the first unplug: " + lens.status().detail;
  for (int k = 1; k <= times; ++k) {
    camhead::vm::write_attribute(udc_file, "\n");
    if (!poll_until(lens,
                    [&](const std::vector<EncoderReading> &) { return !lens.status().connected; }))
      return "unplug " + std::to_string(k) +
             ": still connected after 10 s: " + lens.status().detail;
    // Whatever was still queued from before the unplug drains now.
    std::vector<EncoderReading> old;
    lens.poll(0ms, old);
    const std::int64_t plugged = monotonic_ns();
    camhead::vm::write_attribute(udc_file, udc + "\n");
    std::int64_t there = 0; // when the kernel had it enumerated, first seen
    if (!poll_until(lens, [&](const std::vector<EncoderReading> &r) {
          if (there == 0 && camhead::vm::usb_device_enumerated(serial))
            there = monotonic_ns();
          return lens.status().connected && !r.empty();
        }))
      return "plug " + std::to_string(k) + ": no reading 10 s after it: " + lens.status().detail;
    const std::int64_t now = monotonic_ns();
    back.push_back({double(now - plugged) * 1e-6, double(now - (there ? there : now)) * 1e-6});
    if (kTimed && back.back().enumerated_ms > kBackWithinMs)
      return "plug " + std::to_string(k) + ": the first reading came " +
             std::to_string(back.back().enumerated_ms) + " ms after the board was enumerated";
  }
  const EncoderStatus status = lens.status();
  if (status.reconnects != std::uint64_t(times))
    return std::to_string(status.reconnects) + " reconnects counted for " + std::to_string(times) +
           " plugs";
  return {};
}

} // namespace

int main(int argc, char **argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: camhead_usb_replug_check UDC_ATTRIBUTE UDC SERIAL\n");
    return 2;
  }
  UsbLensConfig config;
  config.serial = argv[3];
  std::vector<Back> back;
  std::string problem;
  try {
    const auto lens = open_usb_lens(config);
    problem = replug(argv[1], argv[2], argv[3], *lens, kReplugs, back);
  } catch (const std::exception &e) {
    problem = e.what();
  }
  std::string detail = problem;
  if (!back.empty()) {
    const auto all = [&](double Back::*of) {
      std::vector<double> v;
      for (const Back &b : back)
        v.push_back(b.*of);
      return camhead::vm::median_and_worst_ms(std::move(v));
    };
    const std::string text = std::to_string(back.size()) + " of " + std::to_string(kReplugs) +
                             " back; enumerated to first reading: " + all(&Back::enumerated_ms) +
                             (kTimed ? "" : " (sanitized: reported, not held)") +
                             "; plug to first reading: " + all(&Back::plug_ms);
    detail = problem.empty() ? text : problem + "; " + text;
  }
  camhead::vm::print_result("usb_replug_backend", problem.empty(), detail);
  // The verdict is the RESULT line. The exit status is left to what the
  // line cannot say (a crash, a sanitizer's report at exit): it fails every
  // check of usb_lens.sh (lab_result.sh), not only this one.
  return 0;
}
