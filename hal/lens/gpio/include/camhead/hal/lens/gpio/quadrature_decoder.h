// x4 quadrature decoding of one encoder axis: A and B lines 90 degrees apart,
// and an optional index (home) line. Pure arithmetic, no device: the libgpiod
// edge source and the simulated twin both feed this class, so what the tests
// prove about it holds for the real encoder.
//
// Convention: the state is (A << 1) | B and counting up is the Gray sequence
// 00 -> 10 -> 11 -> 01 -> 00 (A leads B). `reverse` flips the sign for an
// encoder mounted the other way round.
//
// Input is line levels, not "toggles": every event says "line X now reads v".
// That is what the kernel reports (the v1 GPIO uAPI reads the level when its
// interrupt thread runs), and it makes a bounce on one line harmless: A
// flickering 0-1-0-1 while B is still decodes +1 -1 +1, the right answer.
//
// What cannot be decoded, and how it is counted (missed_edges; the count is
// never moved on a guess):
//   - An illegal transition, both A and B changed between two observations:
//     the encoder moved two steps and the direction is unknown. It arises from
//     a full-state observe() (the idle re-read of the lines) and from an A and
//     a B edge that carry the same timestamp: the kernel queues each line
//     separately, so two edges of one clock tick have no order, and A-then-B
//     is +2 where B-then-A is -2. The first edge's step is taken back.
//   - A duplicate that hides a lost edge. An event that repeats the level its
//     line already has ("same level twice") means the line toggled an even
//     number of times since its last event. If the other line did not change
//     in between, that was a bounce or a glitch whose net motion is zero:
//     nothing to do, counted in `duplicates` only. If the other line changed
//     in between, an edge of this line was probably lost and the step decoded
//     from the other line may have the wrong sign (a lost edge in steady
//     motion costs a whole cycle, 4 counts): counted as a missed edge too. A
//     bounce whose level the kernel read late looks the same; it is then
//     counted as missed although the count is right.
//
// Index: the axis is homed when the qualified index becomes true, i.e. the
// index line is high and, with a gate, A/B are in the gate's state. Judging
// the conjunction of levels rather than the index edge alone makes homing
// independent of the order in which simultaneous index and A/B events arrive
// and of the direction of travel (an index gated to one quarter is entered at
// the same count from either side).
//
// Thread safety: none; one thread (the lens thread) owns each decoder.
#pragma once

#include <cstdint>
#include <optional>

namespace camhead::hal::lens::gpio {

enum class QuadratureLine : std::uint8_t { a, b, index };

// The A/B state in which an index pulse counts, for encoders whose index is
// gated to one quarter of a cycle; `any` takes the index level alone.
enum class IndexGate : std::uint8_t { any, ab00, ab01, ab10, ab11 };

// Levels of one axis' lines, logical (after any active-low inversion).
struct AxisLevels {
  bool a = false, b = false, index = false;

  bool operator==(const AxisLevels &) const = default;
};

// What one A/B state change means. `illegal`: both lines changed.
enum class QuadratureStep : std::int8_t { backward = -1, none = 0, forward = 1, illegal = 2 };

// The full 16-entry x4 table, indexed by (from << 2) | to with states
// (A << 1) | B. Legal single-line changes are +-1, no change is 0, and the
// four double changes (00<->11, 01<->10) are illegal.
[[nodiscard]] constexpr QuadratureStep quadrature_step(unsigned from_ab, unsigned to_ab) {
  using enum QuadratureStep;
  constexpr QuadratureStep kTable[16] = {
      // to:  00        01        10        11
      none,     backward, forward,  illegal,  // from 00
      forward,  none,     illegal,  backward, // from 01
      backward, illegal,  none,     forward,  // from 10
      illegal,  forward,  backward, none,     // from 11
  };
  return kTable[((from_ab & 3u) << 2) | (to_ab & 3u)];
}

struct QuadratureAxisConfig {
  bool reverse = false; // count down where A leads B
  // The count the axis takes when homed. Unset: index pulses are counted but
  // never move the position.
  std::optional<std::int32_t> counts_at_index;
  IndexGate index_gate = IndexGate::any;
  // false: home on the first qualified index after reset()/resync() or
  // request_home(), then only count pulses (an encoder whose index fires once
  // per shaft turn passes it many times over the travel). true: every pulse.
  bool home_on_every_index = false;
};

struct QuadratureCounters {
  std::uint64_t events = 0;       // edge events fed, index included
  std::uint64_t missed_edges = 0; // illegal transitions and lost-edge duplicates
  std::uint64_t duplicates = 0;   // events that repeated their line's level
  std::uint64_t recovered = 0;    // single steps found by observe(): an event never came
  std::uint64_t index_pulses = 0; // qualified index rises
  std::uint64_t homings = 0;      // times the position was set to counts_at_index
};

class QuadratureDecoder {
public:
  QuadratureDecoder() = default;
  explicit QuadratureDecoder(QuadratureAxisConfig config) : config_(config) {}

  // Takes `levels` as the state without counting, sets the position, and
  // forgets homing. An index already qualified at reset does not home: the
  // rise was not seen.
  void reset(AxisLevels levels, std::int32_t position = 0);
  // After a gap in which edges could not be seen (device unplugged): adopts
  // `levels` without counting and keeps the position, but clears homed():
  // the reference is no longer trustworthy until the next index.
  void resync(AxisLevels levels);

  // One event, in time order. Returns true when the position changed (a step,
  // a step taken back, or homing).
  bool on_edge(QuadratureLine line, bool level, std::int64_t t_ns);
  // A full-state observation of all lines (re-reading the lines when idle).
  // A single-line difference is a step whose event never came (counted in
  // `recovered`); a double difference is illegal. Returns the step seen.
  QuadratureStep observe(AxisLevels levels, std::int64_t t_ns);

  // Arms homing again: the next qualified index sets counts_at_index.
  void request_home() { homed_ = false; }

  [[nodiscard]] std::int32_t position() const { return position_; }
  [[nodiscard]] bool homed() const { return homed_; }
  [[nodiscard]] AxisLevels levels() const;
  [[nodiscard]] const QuadratureCounters &counters() const { return counters_; }
  [[nodiscard]] const QuadratureAxisConfig &config() const { return config_; }
  // Raw position at the last qualified index rise, before any homing.
  [[nodiscard]] std::optional<std::int32_t> position_at_last_index() const {
    return last_index_position_;
  }

private:
  static constexpr std::int8_t kNoLine = -1;

  bool apply_step(unsigned to_ab, std::int8_t line, std::int64_t t_ns);
  bool update_index();

  QuadratureAxisConfig config_;
  std::int32_t position_ = 0;
  unsigned ab_ = 0; // (A << 1) | B
  bool index_ = false;
  bool qualified_ = false; // index high and gate satisfied
  bool homed_ = false;
  // The last A/B change: which line (0 A, 1 B, kNoLine after an illegal
  // transition or reset), when, by how much, and the state before it.
  std::int8_t last_line_ = kNoLine;
  std::int64_t last_t_ns_ = 0;
  std::int32_t last_delta_ = 0;
  unsigned before_last_ab_ = 0;
  std::optional<std::int32_t> last_index_position_;
  QuadratureCounters counters_;
};

} // namespace camhead::hal::lens::gpio
