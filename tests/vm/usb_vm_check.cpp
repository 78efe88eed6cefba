// Hardware-lab check of the USB lens backend: reads the FunctionFS board
// (usb_lens_gadget.cpp) through open_usb_lens(), exactly as the pipeline
// would, while usb_lens.sh plugs, unplugs and replugs it by binding and
// unbinding the UDC. Prints one RESULT line per verdict:
//
//   usb_absent_at_start          started before the board: waiting, no error
//   usb_enumerates_and_streams   the board was found, opened and streamed
//   usb_counts_match_trajectory  every reading lies on the gadget's LensRamp,
//                                every index of every connection arrived
//                                (except the corrupted ones), in order
//   usb_clock_mapping            timestamps strictly increase within a
//                                connection (the device clock wraps in each)
//                                and lie between receipt - 2 s and receipt;
//                                the median step is printed, not judged:
//                                under emulation the gadget falls behind its
//                                schedule and catches up (hardware-lab.md:
//                                no rate checks in the VM), and the mapper's
//                                precision is tested in tests/hal/lens/usb/
//   usb_corrupt_report_malformed malformed == the corrupted reports, lost == 0
//   usb_unplug_replug            one reconnect, connected again, the second
//                                connection complete
//
//   camhead_usb_vm_check --count N [--rate HZ] [--corrupt-at K]... [--connections C]
//                        [--serial S] [--timeout-s T] [--ready-file FILE]
//
// --ready-file is created once the absent-board check is done, so that the
// script binds the UDC only then.
// It stops when the last connection has delivered its N readings, or after
// T seconds (then whatever is missing fails).
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "camhead/hal/lens/usb/lens_ramp.h"
#include "camhead/hal/lens/usb/usb_lens.h"
#include "vm_result.h"

namespace {

using namespace camhead::hal::lens;
using camhead::vm::print_result;

struct Options {
  std::uint64_t count = 0;
  std::uint64_t rate_hz = 200;
  std::set<std::uint64_t> corrupt_at;
  std::uint64_t connections = 2;
  std::optional<std::string> serial;
  int timeout_s = 60;
  std::string ready_file; // created once the absent-board check is done
};

[[noreturn]] void usage(const std::string &problem) {
  std::fprintf(stderr,
               "usb_vm_check: %s\nusage: camhead_usb_vm_check --count N [--corrupt-at K]... "
               "[--connections C] [--serial S] [--timeout-s T] [--ready-file FILE]\n",
               problem.c_str());
  std::exit(2);
}

Options parse_options(int argc, char **argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    if (i + 1 >= argc) {
      usage(option + " needs a value");
    }
    const std::string value = argv[++i];
    const auto number = [&] {
      char *end = nullptr;
      const unsigned long long n = std::strtoull(value.c_str(), &end, 0);
      if (end == value.c_str() || *end != '\0') {
        usage(option + ": \"" + value + "\" is not a number");
      }
      return static_cast<std::uint64_t>(n);
    };
    if (option == "--count") {
      o.count = number();
    } else if (option == "--rate") {
      o.rate_hz = number();
    } else if (option == "--corrupt-at") {
      o.corrupt_at.insert(number());
    } else if (option == "--connections") {
      o.connections = number();
    } else if (option == "--serial") {
      o.serial = value;
    } else if (option == "--timeout-s") {
      o.timeout_s = static_cast<int>(number());
    } else if (option == "--ready-file") {
      o.ready_file = value;
    } else {
      usage("unknown option " + option);
    }
  }
  if (o.count == 0 || o.connections == 0 || o.rate_hz == 0) {
    usage("--count, --rate and --connections must be at least 1");
  }
  return o;
}

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

struct Sample {
  std::int64_t t_ns = 0;
  std::int64_t index = -1;      // on the ramp, or -1
  std::int64_t received_ns = 0; // when poll() handed it over
};

// Readings split where the ramp index falls back: the board restarted.
using Connection = std::vector<Sample>;

std::string expected_indices_problem(const Connection &c, std::size_t number, const Options &o) {
  std::uint64_t want = 0;
  const auto skip = [&] {
    while (number == 1 && o.corrupt_at.count(want) != 0) {
      ++want;
    }
  };
  skip();
  for (const Sample &s : c) {
    if (s.index != static_cast<std::int64_t>(want)) {
      return "connection " + std::to_string(number) + ": expected index " + std::to_string(want) +
             ", got " + std::to_string(s.index);
    }
    ++want;
    skip();
  }
  if (want < o.count) {
    return "connection " + std::to_string(number) + ": stopped at index " + std::to_string(want) +
           " of " + std::to_string(o.count);
  }
  return {};
}

std::size_t expected_readings(std::size_t number, const Options &o) {
  std::size_t corrupted = 0;
  for (const std::uint64_t k : o.corrupt_at) {
    corrupted += k < o.count ? 1 : 0;
  }
  return number == 1 ? o.count - corrupted : o.count;
}

} // namespace

int main(int argc, char **argv) {
  const Options o = parse_options(argc, argv);
  UsbLensConfig config;
  config.serial = o.serial;
  const std::string name = usb_lens_name(config);
  const auto lens = open_usb_lens(config);

  // Started before the UDC is bound: the board is not there yet.
  const EncoderStatus first = lens->status();
  const bool absent_ok = !first.connected && first.detail == name + ": not connected, waiting";
  print_result("usb_absent_at_start", absent_ok, first.detail);
  if (!o.ready_file.empty()) {
    if (FILE *f = std::fopen(o.ready_file.c_str(), "w")) {
      std::fclose(f);
    }
  }

  std::vector<Connection> connections;
  std::string connected_detail;
  bool seen_disconnect = false, was_connected = false;
  std::uint64_t off_ramp = 0;
  const std::int64_t deadline = monotonic_ns() + std::int64_t{o.timeout_s} * 1'000'000'000;
  std::vector<EncoderReading> out;
  while (monotonic_ns() < deadline) {
    out.clear();
    lens->poll(std::chrono::milliseconds(100), out);
    const std::int64_t now = monotonic_ns();
    for (const EncoderReading &r : out) {
      Sample s{r.t_ns, -1, now};
      if (r.focus && r.iris && r.zoom) {
        if (const auto i = LensRamp{}.index_of(LensAxes{*r.focus, *r.iris, *r.zoom})) {
          s.index = *i;
        }
      }
      if (s.index < 0) {
        ++off_ramp;
        continue;
      }
      if (connections.empty() || s.index <= connections.back().back().index) {
        connections.emplace_back();
      }
      connections.back().push_back(s);
    }
    const EncoderStatus st = lens->status();
    if (st.connected && connected_detail.empty()) {
      connected_detail = st.detail;
    }
    seen_disconnect = seen_disconnect || (was_connected && !st.connected);
    was_connected = st.connected;
    if (connections.size() >= o.connections &&
        connections.back().size() >= expected_readings(connections.size(), o)) {
      break;
    }
  }
  const EncoderStatus last = lens->status();

  std::size_t total = 0;
  for (const Connection &c : connections) {
    total += c.size();
  }
  print_result("usb_enumerates_and_streams", !connected_detail.empty() && total > 0,
               (connected_detail.empty() ? "never connected: " + last.detail : connected_detail) +
                   "; " + std::to_string(total) + " readings");

  // Counts: every reading on the ramp, every index of every connection.
  std::string problem;
  if (off_ramp != 0) {
    problem = std::to_string(off_ramp) + " readings off the scripted ramp";
  } else if (connections.size() != o.connections) {
    problem = std::to_string(connections.size()) + " connections seen, expected " +
              std::to_string(o.connections);
  }
  for (std::size_t i = 0; problem.empty() && i < connections.size(); ++i) {
    problem = expected_indices_problem(connections[i], i + 1, o);
  }
  std::string sizes;
  for (const Connection &c : connections) {
    sizes += (sizes.empty() ? "" : " + ") + std::to_string(c.size());
  }
  print_result("usb_counts_match_trajectory", problem.empty(),
               problem.empty() ? std::to_string(connections.size()) + " connections, " + sizes +
                                     " readings, all on the ramp"
                               : problem);

  // Clock mapping: CLOCK_MONOTONIC, increasing through the device clock's
  // wrap, never after receipt. The gadget's device clock is this guest's
  // CLOCK_MONOTONIC plus an offset, so the mapping has a true answer here.
  problem.clear();
  std::vector<std::int64_t> steps;
  for (std::size_t i = 0; problem.empty() && i < connections.size(); ++i) {
    const Connection &c = connections[i];
    for (std::size_t k = 0; k < c.size(); ++k) {
      if (c[k].t_ns > c[k].received_ns || c[k].t_ns < c[k].received_ns - 2'000'000'000) {
        problem = "connection " + std::to_string(i + 1) + " index " + std::to_string(c[k].index) +
                  ": t_ns " + std::to_string(c[k].t_ns) + " is not within 2 s before its receipt " +
                  std::to_string(c[k].received_ns);
        break;
      }
      if (k > 0) {
        if (c[k].t_ns <= c[k - 1].t_ns) {
          problem = "connection " + std::to_string(i + 1) + ": t_ns goes back at index " +
                    std::to_string(c[k].index);
          break;
        }
        steps.push_back(c[k].t_ns - c[k - 1].t_ns);
      }
    }
  }
  // Information only: the gadget latches on an absolute schedule, so under
  // load its steps stray from the period in both directions.
  const std::int64_t period_ns = 1'000'000'000 / static_cast<std::int64_t>(o.rate_hz);
  std::int64_t median_ns = 0;
  if (problem.empty() && steps.empty()) {
    problem = "no two readings in one connection";
  } else if (problem.empty()) {
    std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2),
                     steps.end());
    median_ns = steps[steps.size() / 2];
  }
  print_result("usb_clock_mapping", problem.empty(),
               problem.empty() ? "strictly increasing across the device clock wrap, median step " +
                                     std::to_string(median_ns / 1000) + " us (period " +
                                     std::to_string(period_ns / 1000) + " us)"
                               : problem);

  const std::size_t corrupted = o.count - expected_readings(1, o);
  print_result("usb_corrupt_report_malformed", last.malformed == corrupted && last.lost == 0,
               "malformed=" + std::to_string(last.malformed) + " (expected " +
                   std::to_string(corrupted) + ") lost=" + std::to_string(last.lost));

  const bool complete = connections.size() == o.connections &&
                        connections.back().size() == expected_readings(o.connections, o);
  print_result(
      "usb_unplug_replug", last.reconnects == o.connections - 1 && last.connected && complete,
      "reconnects=" + std::to_string(last.reconnects) +
          (seen_disconnect ? ", saw the board go away" : ", never saw it go away") +
          ", last connection " + (complete ? "complete" : "incomplete") + "; " + last.detail);
  return 0;
}
