// Hardware-lab infrastructure check: edges made by a kernel gpio-sim chip
// reach libgpiod 1.6 as real edge events, one per level change, in order,
// with nothing extra. Independent of camhead's GPIO backend, so that a
// failure here points at the lab (module, configfs, libgpiod), not at the
// decoder.
//
//   camhead_vm_gpio_sim_smoke      prints RESULT gpio_sim_edges
#include <chrono>
#include <cstdint>
#include <ctime>
#include <memory>
#include <stdexcept>
#include <string>

#include <gpiod.h>

#include "gpio_sim.h"
#include "vm_result.h"

namespace {

using camhead::vm::GpioSim;

struct ChipCloser {
  void operator()(gpiod_chip *chip) const { gpiod_chip_close(chip); }
};
using ChipPtr = std::unique_ptr<gpiod_chip, ChipCloser>;

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

// Waits up to a second for the next event on `line` and checks its direction.
// Returns the kernel's timestamp.
std::int64_t expect_event(gpiod_line *line, bool rising, int edge) {
  const timespec timeout{1, 0};
  const int ready = gpiod_line_event_wait(line, &timeout);
  if (ready <= 0) {
    throw std::runtime_error("edge " + std::to_string(edge) + ": no event within 1 s");
  }
  gpiod_line_event event{};
  if (gpiod_line_event_read(line, &event) != 0) {
    throw std::runtime_error("edge " + std::to_string(edge) + ": gpiod_line_event_read failed");
  }
  const int want = rising ? GPIOD_LINE_EVENT_RISING_EDGE : GPIOD_LINE_EVENT_FALLING_EDGE;
  if (event.event_type != want) {
    throw std::runtime_error("edge " + std::to_string(edge) + ": expected " +
                             (rising ? "rising" : "falling") + ", got the other");
  }
  return std::int64_t{event.ts.tv_sec} * 1'000'000'000 + event.ts.tv_nsec;
}

std::string run() {
  const GpioSim sim("lab-smoke", 2, "camhead-lab-smoke");
  ChipPtr chip(gpiod_chip_open_lookup(sim.chip_name().c_str()));
  if (!chip) {
    throw std::runtime_error("cannot open " + sim.chip_name());
  }
  gpiod_line *line = gpiod_chip_get_line(chip.get(), 0);
  if (line == nullptr || gpiod_line_request_both_edges_events(line, "camhead-lab") != 0) {
    throw std::runtime_error("cannot request both-edge events on " + sim.chip_name() + " line 0");
  }

  // One edge at a time: pull, then the event, timed from the write.
  constexpr int kPaced = 40;
  std::int64_t latency_sum = 0;
  for (int edge = 0; edge < kPaced; ++edge) {
    const bool rising = edge % 2 == 0;
    const std::int64_t written = monotonic_ns();
    sim.set_pull(0, rising);
    latency_sum += expect_event(line, rising, edge) - written;
  }

  // A burst within the kernel's per-line queue (16 events for the v1 uAPI
  // that libgpiod 1.6 uses): all of them arrive, in order.
  constexpr int kBurst = 12;
  for (int edge = 0; edge < kBurst; ++edge) {
    sim.set_pull(0, edge % 2 == 0);
  }
  for (int edge = 0; edge < kBurst; ++edge) {
    expect_event(line, edge % 2 == 0, kPaced + edge);
  }

  // Nothing extra.
  const timespec quiet{0, 200'000'000};
  if (gpiod_line_event_wait(line, &quiet) != 0) {
    throw std::runtime_error("an event arrived after the last edge");
  }
  gpiod_line_release(line);
  return std::to_string(kPaced) + " paced and " + std::to_string(kBurst) + " queued edges on " +
         sim.chip_name() + " line 0, in order; " + std::to_string(latency_sum / kPaced / 1000) +
         " us from pull write to edge timestamp";
}

} // namespace

int main() {
  try {
    camhead::vm::print_result("gpio_sim_edges", true, run());
  } catch (const std::exception &error) {
    camhead::vm::print_result("gpio_sim_edges", false, error.what());
  }
  return 0;
}
