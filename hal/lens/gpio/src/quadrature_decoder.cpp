// x4 quadrature decoding. See quadrature_decoder.h for the convention and for
// what is counted as a missed edge. on_edge() is the hot path: a few branches
// and no allocation, so a recorded 1 MHz burst decodes far faster than real
// time (tests/hal/lens/gpio/recording_test.cpp prints the rate).
#include "camhead/hal/lens/gpio/quadrature_decoder.h"

namespace camhead::hal::lens::gpio {
namespace {

constexpr unsigned kBitA = 2u, kBitB = 1u;

constexpr unsigned state_of(AxisLevels levels) {
  return (levels.a ? kBitA : 0u) | (levels.b ? kBitB : 0u);
}

constexpr bool gate_open(IndexGate gate, unsigned ab) {
  switch (gate) {
  case IndexGate::any:
    return true;
  case IndexGate::ab00:
    return ab == 0u;
  case IndexGate::ab01:
    return ab == 1u;
  case IndexGate::ab10:
    return ab == 2u;
  case IndexGate::ab11:
    return ab == 3u;
  }
  return false;
}

// The table is the single source of the decoding rules; these checks pin the
// convention the header documents.
static_assert(quadrature_step(0b00, 0b10) == QuadratureStep::forward);
static_assert(quadrature_step(0b10, 0b11) == QuadratureStep::forward);
static_assert(quadrature_step(0b11, 0b01) == QuadratureStep::forward);
static_assert(quadrature_step(0b01, 0b00) == QuadratureStep::forward);
static_assert(quadrature_step(0b00, 0b11) == QuadratureStep::illegal);
static_assert(quadrature_step(0b01, 0b10) == QuadratureStep::illegal);

} // namespace

void QuadratureDecoder::reset(AxisLevels levels, std::int32_t position) {
  counters_ = {};
  position_ = position;
  last_index_position_.reset();
  resync(levels);
}

void QuadratureDecoder::resync(AxisLevels levels) {
  ab_ = state_of(levels);
  index_ = levels.index;
  // Already on the index: not a rise we saw, so no homing from it.
  qualified_ = index_ && gate_open(config_.index_gate, ab_);
  homed_ = false;
  last_line_ = kNoLine;
  last_delta_ = 0;
}

AxisLevels QuadratureDecoder::levels() const {
  return AxisLevels{(ab_ & kBitA) != 0, (ab_ & kBitB) != 0, index_};
}

bool QuadratureDecoder::on_edge(QuadratureLine line, bool level, std::int64_t t_ns) {
  ++counters_.events;
  if (line == QuadratureLine::index) {
    index_ = level;
    return update_index();
  }
  const std::int8_t id = line == QuadratureLine::a ? 0 : 1;
  const unsigned bit = id == 0 ? kBitA : kBitB;
  const unsigned to = level ? (ab_ | bit) : (ab_ & ~bit);
  if (to == ab_) {
    // Same level twice: the line toggled an even number of times unseen.
    ++counters_.duplicates;
    if (last_line_ != kNoLine && last_line_ != id) {
      // The other line moved in between: an edge of this line was lost and
      // the step decoded since may have the wrong sign. Counted once.
      ++counters_.missed_edges;
      last_line_ = kNoLine;
    }
    return false;
  }
  return apply_step(to, id, t_ns);
}

QuadratureStep QuadratureDecoder::observe(AxisLevels levels, std::int64_t t_ns) {
  const unsigned to = state_of(levels);
  const QuadratureStep step = quadrature_step(ab_, to);
  std::int8_t line = kNoLine;
  if (step == QuadratureStep::forward || step == QuadratureStep::backward) {
    ++counters_.recovered;
    line = (ab_ ^ to) == kBitA ? 0 : 1;
  }
  index_ = levels.index;
  apply_step(to, line, t_ns);
  return step;
}

bool QuadratureDecoder::apply_step(unsigned to_ab, std::int8_t line, std::int64_t t_ns) {
  // An A and a B edge with one timestamp: the state went from before the
  // previous edge to `to_ab` with both lines changed and no order between
  // them. The table calls that illegal; take the previous step back.
  if (line != kNoLine && last_line_ != kNoLine && last_line_ != line && t_ns == last_t_ns_ &&
      quadrature_step(before_last_ab_, to_ab) == QuadratureStep::illegal) {
    const bool moved = last_delta_ != 0;
    position_ -= last_delta_;
    ++counters_.missed_edges;
    ab_ = to_ab;
    last_line_ = kNoLine;
    last_delta_ = 0;
    return update_index() || moved;
  }

  const QuadratureStep step = quadrature_step(ab_, to_ab);
  if (step == QuadratureStep::illegal) {
    ++counters_.missed_edges;
    ab_ = to_ab;
    last_line_ = kNoLine;
    last_delta_ = 0;
    return update_index();
  }
  if (step == QuadratureStep::none) {
    return update_index();
  }
  const std::int32_t delta =
      config_.reverse ? -static_cast<std::int32_t>(step) : static_cast<std::int32_t>(step);
  before_last_ab_ = ab_;
  ab_ = to_ab;
  position_ += delta;
  last_line_ = line;
  last_t_ns_ = t_ns;
  last_delta_ = delta;
  update_index();
  return true;
}

bool QuadratureDecoder::update_index() {
  const bool qualified = index_ && gate_open(config_.index_gate, ab_);
  if (qualified == qualified_) {
    return false;
  }
  qualified_ = qualified;
  if (!qualified) {
    return false;
  }
  ++counters_.index_pulses;
  last_index_position_ = position_;
  if (!config_.counts_at_index || (homed_ && !config_.home_on_every_index)) {
    return false;
  }
  ++counters_.homings;
  homed_ = true;
  const bool moved = position_ != *config_.counts_at_index;
  position_ = *config_.counts_at_index;
  // A step taken back after homing must not undo the reference.
  last_line_ = kNoLine;
  last_delta_ = 0;
  return moved;
}

} // namespace camhead::hal::lens::gpio
