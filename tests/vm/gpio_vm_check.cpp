// Hardware-lab check of the GPIO quadrature backend (hal/lens/gpio) against
// the kernel's GPIO character device: open_gpio_quadrature() reads a gpio-sim
// chip whose A, B and index lines this program moves through their sysfs
// pulls, and the counts and missed-edge counters must come out exactly.
//
// Exactness holds because the guest has one CPU: the kernel's interrupt
// thread records each edge before this program writes the next
// (run_lab.sh). The encoder is polled only where a scenario says so; between
// polls edges wait in the kernel's per-line queue, which holds 16 (v1 uAPI).
// The lost-edge and missed-edge scenarios overflow that queue on purpose:
// the decoder then never sees a state (its event was dropped), and the
// encoder's idle re-read of the lines must notice, recovering a single lost
// step and counting two lost steps (a skipped state: A and B both changed,
// direction unknown) as a missed edge without moving the count. Last, the
// chip is removed and brought back (gpio-sim's `live`), as an unplugged
// expander would: the encoder must reconnect by label and count on, unhomed.
//
//   camhead_gpio_vm_check     prints RESULT gpio_quadrature_* lines
#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "camhead/hal/lens/gpio/gpio_quadrature.h"
#include "gpio_sim.h"
#include "vm_result.h"

namespace {

namespace gpio = camhead::hal::lens::gpio;
using camhead::hal::lens::EncoderReading;
using camhead::vm::GpioSim;
using camhead::vm::print_result;

constexpr unsigned kLineA = 0, kLineB = 1, kLineIndex = 2;
constexpr std::int32_t kCountsAtIndex = 1000;
constexpr int kQueue = 16; // kernel events per line (v1 uAPI)
// Full cycles that exactly fill both lines' queues: 2 A and 2 B edges each.
constexpr int kCyclesToFill = kQueue / 2;

struct Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void expect(bool ok, const std::string &what) {
  if (!ok) {
    throw Failure(what);
  }
}

// The gpio-sim chip, the encoder reading it, and the signal this program
// drives, one quadrature step at a time (Gray order 00 -> 10 -> 11 -> 01 is
// forward: quadrature_decoder.h).
class Rig {
public:
  Rig() : sim_("lab-quadrature", 4, "camhead-lab-quadrature") {
    gpio::GpioQuadratureConfig config;
    config.chip = sim_.label(); // by label, as a board file would name it
    gpio::GpioQuadratureAxis focus;
    focus.line_a = kLineA;
    focus.line_b = kLineB;
    focus.line_index = kLineIndex;
    focus.decoder.counts_at_index = kCountsAtIndex;
    config.focus = focus;
    config.reopen_interval = std::chrono::milliseconds(100);
    encoder_ = gpio::open_gpio_quadrature(config);
  }

  [[nodiscard]] const GpioSim &sim() const { return sim_; }
  [[nodiscard]] gpio::QuadratureEncoder &encoder() { return *encoder_; }
  [[nodiscard]] const gpio::QuadratureDecoder &decoder() const {
    return encoder_->decoder(gpio::LensAxis::focus);
  }
  [[nodiscard]] std::int32_t position() const { return decoder().position(); }

  // One quadrature step of the simulated encoder: +1 forward, -1 backward.
  void step(int direction) {
    static constexpr unsigned kForward[4] = {0b10, 0b00, 0b11, 0b01}; // next of 00,01,10,11
    static constexpr unsigned kBackward[4] = {0b01, 0b11, 0b00, 0b10};
    const unsigned to = direction > 0 ? kForward[ab_] : kBackward[ab_];
    if ((to ^ ab_) & 0b10) {
      sim_.set_pull(kLineA, (to & 0b10) != 0);
    } else {
      sim_.set_pull(kLineB, (to & 0b01) != 0);
    }
    ab_ = to;
  }
  void steps(int count, int direction) {
    for (int i = 0; i < count; ++i) {
      step(direction);
    }
  }

  // The chip goes away and comes back with its lines low (gpio_sim.h).
  void unplug() { sim_.set_live(false); }
  void replug() {
    sim_.set_live(true);
    ab_ = 0;
  }

  // Polls until `done` holds, for at most `limit`.
  bool poll_until(const std::function<bool()> &done, std::chrono::milliseconds limit) {
    std::vector<EncoderReading> readings;
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (!done()) {
      if (std::chrono::steady_clock::now() >= deadline) {
        return false;
      }
      encoder_->poll(std::chrono::milliseconds(20), readings);
    }
    return true;
  }

  // Polls until the encoder has nothing new to say: no new event, the count
  // unchanged and the idle re-read done (a still encoder is still reported
  // every still_interval, so new readings alone do not mean motion); returns
  // the readings.
  std::vector<EncoderReading> settle() {
    std::vector<EncoderReading> readings;
    for (int round = 0; round < 200; ++round) {
      const std::uint64_t before_events = decoder().counters().events;
      const std::int32_t before_position = position();
      encoder_->poll(std::chrono::milliseconds(20), readings);
      if (decoder().counters().events == before_events && position() == before_position &&
          round > 0) {
        return readings;
      }
    }
    throw Failure("the encoder kept moving for 200 polls");
  }

  // Settles and checks that the last reading carries the decoder's position.
  std::int32_t settled_position() {
    const std::vector<EncoderReading> readings = settle();
    const std::int32_t position = decoder().position();
    if (!readings.empty()) {
      expect(readings.back().focus == position,
             "last reading's focus " + std::to_string(readings.back().focus.value_or(-1)) +
                 " differs from the decoder's position " + std::to_string(position));
    }
    return position;
  }

private:
  GpioSim sim_;
  std::unique_ptr<gpio::QuadratureEncoder> encoder_;
  unsigned ab_ = 0; // gpio-sim lines start pulled down
};

// Counters before a scenario, to report what it changed.
struct Snapshot {
  std::int32_t position;
  gpio::QuadratureCounters counters;
};

Snapshot snapshot(const Rig &rig) {
  return {rig.position(), rig.decoder().counters()};
}

std::string counts_text(const Snapshot &before, const Rig &rig) {
  const gpio::QuadratureCounters &now = rig.decoder().counters();
  return "count " + std::to_string(before.position) + " -> " + std::to_string(rig.position()) +
         ", missed edges +" + std::to_string(now.missed_edges - before.counters.missed_edges) +
         ", recovered +" + std::to_string(now.recovered - before.counters.recovered) +
         ", duplicates +" + std::to_string(now.duplicates - before.counters.duplicates);
}

// A scenario moves the signal and checks the encoder; `expected` is the count
// change, `missed`/`recovered` the counter changes it must produce.
void check_counts(Rig &rig, const Snapshot &before, std::int32_t expected, std::uint64_t missed,
                  std::uint64_t recovered) {
  const std::int32_t position = rig.settled_position();
  const gpio::QuadratureCounters &now = rig.decoder().counters();
  const std::string got = counts_text(before, rig);
  expect(position - before.position == expected,
         got + "; expected a change of " + std::to_string(expected));
  expect(now.missed_edges - before.counters.missed_edges == missed,
         got + "; expected missed edges +" + std::to_string(missed));
  expect(now.recovered - before.counters.recovered == recovered,
         got + "; expected recovered +" + std::to_string(recovered));
  expect(now.duplicates == before.counters.duplicates, got + "; expected no duplicates");
}

std::string open_check(Rig &rig) {
  // The axis homes on its index (counts_at_index), so until the index check
  // below it counts from wherever it started: the encoder withholds it, and
  // the connect reading (quadrature_encoder.h) carries nothing.
  const std::vector<EncoderReading> readings = rig.settle();
  expect(readings.empty(),
         "expected no reading before homing, got " + std::to_string(readings.size()));
  const auto status = rig.encoder().status();
  expect(status.connected, "not connected: " + status.detail);
  expect(status.detail.find("not homed") != std::string::npos,
         "status does not say the axis is not homed: " + status.detail);
  return "chip by label " + rig.sim().label() + " (" + rig.sim().chip_name() + "); " +
         status.detail;
}

std::string forward_check(Rig &rig) {
  const Snapshot before = snapshot(rig);
  rig.steps(4 * 4, +1); // four cycles, queued in the kernel, then read at once
  check_counts(rig, before, 16, 0, 0);
  return counts_text(before, rig) + " after 16 forward steps read in one batch";
}

std::string backward_check(Rig &rig) {
  const Snapshot before = snapshot(rig);
  rig.steps(24, -1);
  check_counts(rig, before, -24, 0, 0);
  return counts_text(before, rig) + " after 24 backward steps";
}

// Reversals in every state, one edge per poll: each reading must follow.
std::string reversal_check(Rig &rig) {
  const Snapshot before = snapshot(rig);
  std::int32_t expected = before.position;
  int readings = 0;
  for (int state = 0; state < 4; ++state) {
    for (const int direction : {+1, -1, -1, +1, +1}) {
      rig.step(direction);
      expected += direction;
      const std::int32_t position = rig.settled_position();
      expect(position == expected, "after a step of " + std::to_string(direction) + " count is " +
                                       std::to_string(position) + ", expected " +
                                       std::to_string(expected));
      ++readings;
    }
  }
  check_counts(rig, before, 4, 0, 0);
  return counts_text(before, rig) + "; " + std::to_string(readings) +
         " single steps with reversals in all four states, each read back";
}

std::string index_check(Rig &rig) {
  const Snapshot before = snapshot(rig);
  expect(!rig.encoder().homed(gpio::LensAxis::focus), "homed before any index pulse");
  rig.sim().set_pull(kLineIndex, true);
  rig.sim().set_pull(kLineIndex, false);
  const std::int32_t homed_at = rig.settled_position();
  expect(homed_at == kCountsAtIndex, "count " + std::to_string(homed_at) +
                                         " after the index pulse, expected " +
                                         std::to_string(kCountsAtIndex));
  expect(rig.encoder().homed(gpio::LensAxis::focus), "not homed after the index pulse");
  rig.steps(5, +1);
  const std::int32_t after = rig.settled_position();
  expect(after == kCountsAtIndex + 5, "count " + std::to_string(after) + " 5 steps after homing");
  const gpio::QuadratureCounters &now = rig.decoder().counters();
  expect(now.index_pulses - before.counters.index_pulses == 1 &&
             now.homings - before.counters.homings == 1,
         "expected one index pulse and one homing");
  return "index pulse at count " + std::to_string(before.position) + " homed to " +
         std::to_string(homed_at) + ", then " + std::to_string(after) + "; " +
         rig.encoder().status().detail;
}

// The queues hold exactly kCyclesToFill cycles; one step more is dropped by
// the kernel, and only the idle re-read of the lines can find it.
std::string lost_edge_check(Rig &rig) {
  const Snapshot before = snapshot(rig);
  rig.steps(kCyclesToFill * 4 + 1, +1);
  check_counts(rig, before, kCyclesToFill * 4 + 1, 0, 1);
  return counts_text(before, rig) + " after " + std::to_string(kCyclesToFill * 4 + 1) +
         " steps, the last one's event dropped by the full kernel queue; status lost " +
         std::to_string(rig.encoder().status().lost);
}

// Two steps more: both lines changed unseen, the state in between skipped.
// The direction is unknowable, so the count must not move for them.
std::string missed_edge_check(Rig &rig) {
  const Snapshot before = snapshot(rig);
  rig.steps(kCyclesToFill * 4 + 2, +1);
  check_counts(rig, before, kCyclesToFill * 4, 1, 0);
  return counts_text(before, rig) + " after " + std::to_string(kCyclesToFill * 4 + 2) +
         " steps, the last two dropped (a skipped state); status missed_edges " +
         std::to_string(rig.encoder().status().missed_edges);
}

// The chip disappears with the lines requested, as a GPIO expander on a
// cable would: the encoder must notice, keep retrying, and come back counting
// from where it was but no longer homed.
std::string unplug_check(Rig &rig) {
  const Snapshot before = snapshot(rig);
  gpio::QuadratureEncoder &encoder = rig.encoder();
  const std::uint64_t reconnects = encoder.status().reconnects;
  rig.unplug();
  expect(rig.poll_until([&] { return !encoder.status().connected; }, std::chrono::seconds(5)),
         "still connected 5 s after the chip was removed");
  const std::string gone = encoder.status().detail;
  rig.replug();
  expect(rig.poll_until([&] { return encoder.status().connected; }, std::chrono::seconds(5)),
         "not reconnected 5 s after the chip came back: " + encoder.status().detail);
  expect(encoder.status().reconnects == reconnects + 1, "reconnects did not go up by one");
  expect(!encoder.homed(gpio::LensAxis::focus), "still homed after the chip came back");
  expect(rig.settled_position() == before.position, "count " + std::to_string(rig.position()) +
                                                        " after reconnecting, expected " +
                                                        std::to_string(before.position));
  rig.steps(8, +1);
  check_counts(rig, before, 8, 0, 0);
  return "while away: \"" + gone + "\"; back as " + rig.sim().chip_name() + ", " +
         counts_text(before, rig) + " after 8 more steps; " + encoder.status().detail;
}

const std::vector<std::pair<const char *, std::function<std::string(Rig &)>>> kScenarios = {
    {"gpio_quadrature_open", open_check},
    {"gpio_quadrature_forward", forward_check},
    {"gpio_quadrature_backward", backward_check},
    {"gpio_quadrature_reversal", reversal_check},
    {"gpio_quadrature_index", index_check},
    {"gpio_quadrature_lost_edge", lost_edge_check},
    {"gpio_quadrature_missed_edge", missed_edge_check},
    {"gpio_quadrature_unplug", unplug_check},
};

} // namespace

int main() {
  std::unique_ptr<Rig> rig;
  try {
    rig = std::make_unique<Rig>();
  } catch (const std::exception &error) {
    for (const auto &[name, scenario] : kScenarios) {
      print_result(name, false, std::string("setting up: ") + error.what());
    }
    return 0;
  }
  // Scenarios measure changes, so one failing leaves the next ones meaningful.
  for (const auto &[name, scenario] : kScenarios) {
    try {
      print_result(name, true, scenario(*rig));
    } catch (const std::exception &error) {
      print_result(name, false, error.what());
    }
  }
  return 0;
}
