// The x4 decoder on hand-made edge sequences: every one of the 16 transitions,
// full cycles both ways, reversal, the reverse flag, bounces, duplicates and
// every way an edge can be missed.
#include <array>
#include <cstdint>
#include <vector>

#include "camhead/hal/lens/gpio/quadrature_decoder.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens::gpio {
namespace {

using Line = QuadratureLine;

QuadratureAxisConfig homing(std::int32_t counts_at_index, IndexGate gate = IndexGate::any,
                            bool every = false) {
  QuadratureAxisConfig c;
  c.counts_at_index = counts_at_index;
  c.index_gate = gate;
  c.home_on_every_index = every;
  return c;
}

AxisLevels ab(unsigned state) {
  return AxisLevels{(state & 2u) != 0, (state & 1u) != 0, false};
}

// The forward Gray sequence as written in every encoder datasheet:
// AB = 00, 10, 11, 01. Its position in the cycle, independent of the table.
int cycle_position(unsigned state) {
  constexpr std::array<unsigned, 4> kForward = {0b00, 0b10, 0b11, 0b01};
  for (int i = 0; i < 4; ++i) {
    if (kForward[static_cast<std::size_t>(i)] == state) {
      return i;
    }
  }
  return -1;
}

QuadratureStep expected_step(unsigned from, unsigned to) {
  switch ((cycle_position(to) - cycle_position(from) + 4) % 4) {
  case 0:
    return QuadratureStep::none;
  case 1:
    return QuadratureStep::forward;
  case 3:
    return QuadratureStep::backward;
  default:
    return QuadratureStep::illegal;
  }
}

// Steps `n` counts from the decoder's current state with one event per
// step, 1 us apart, starting at *t.
void step(QuadratureDecoder &d, int n, std::int64_t *t) {
  for (int i = 0; i < (n < 0 ? -n : n); ++i) {
    const AxisLevels l = d.levels();
    const unsigned from = (l.a ? 2u : 0u) | (l.b ? 1u : 0u);
    const int pos = (cycle_position(from) + (n > 0 ? 1 : 3)) % 4;
    constexpr std::array<unsigned, 4> kForward = {0b00, 0b10, 0b11, 0b01};
    const unsigned to = kForward[static_cast<std::size_t>(pos)];
    const Line line = ((from ^ to) & 2u) != 0 ? Line::a : Line::b;
    d.on_edge(line, line == Line::a ? (to & 2u) != 0 : (to & 1u) != 0, *t += 1000);
  }
}

TEST(QuadratureTable, AllSixteenTransitions) {
  int legal = 0, illegal = 0, none = 0;
  for (unsigned from = 0; from < 4; ++from) {
    for (unsigned to = 0; to < 4; ++to) {
      SCOPED_TRACE(testing::Message() << "from " << from << " to " << to);
      const QuadratureStep s = quadrature_step(from, to);
      EXPECT_EQ(s, expected_step(from, to));
      legal += s == QuadratureStep::forward || s == QuadratureStep::backward;
      illegal += s == QuadratureStep::illegal;
      none += s == QuadratureStep::none;
    }
  }
  EXPECT_EQ(legal, 8);
  EXPECT_EQ(illegal, 4);
  EXPECT_EQ(none, 4);
  // A few spelled out, straight from the datasheet sequence.
  EXPECT_EQ(quadrature_step(0b00, 0b10), QuadratureStep::forward);
  EXPECT_EQ(quadrature_step(0b10, 0b00), QuadratureStep::backward);
  EXPECT_EQ(quadrature_step(0b01, 0b00), QuadratureStep::forward);
  EXPECT_EQ(quadrature_step(0b11, 0b00), QuadratureStep::illegal);
}

TEST(QuadratureDecoder, EveryTransitionThroughObserve) {
  for (unsigned from = 0; from < 4; ++from) {
    for (unsigned to = 0; to < 4; ++to) {
      SCOPED_TRACE(testing::Message() << "from " << from << " to " << to);
      QuadratureDecoder d;
      d.reset(ab(from), 100);
      const QuadratureStep s = d.observe(ab(to), 1000);
      EXPECT_EQ(s, expected_step(from, to));
      const int delta = s == QuadratureStep::illegal ? 0 : static_cast<int>(s);
      EXPECT_EQ(d.position(), 100 + delta);
      EXPECT_EQ(d.counters().missed_edges, s == QuadratureStep::illegal ? 1u : 0u);
      EXPECT_EQ(d.levels(), ab(to)); // the observed state is adopted either way
    }
  }
}

TEST(QuadratureDecoder, EverySingleLineEventFromEveryState) {
  // 4 states x 2 lines x 2 levels: 8 legal steps and 8 duplicates.
  for (unsigned from = 0; from < 4; ++from) {
    for (const Line line : {Line::a, Line::b}) {
      for (const bool level : {false, true}) {
        SCOPED_TRACE(testing::Message() << "from " << from << " line "
                                        << (line == Line::a ? "A" : "B") << " level " << level);
        QuadratureDecoder d;
        d.reset(ab(from));
        const unsigned bit = line == Line::a ? 2u : 1u;
        const unsigned to = level ? (from | bit) : (from & ~bit);
        const bool moved = d.on_edge(line, level, 1000);
        EXPECT_EQ(moved, to != from);
        EXPECT_EQ(d.position(), static_cast<int>(expected_step(from, to)));
        EXPECT_EQ(d.counters().duplicates, to == from ? 1u : 0u);
        EXPECT_EQ(d.counters().missed_edges, 0u);
      }
    }
  }
}

TEST(QuadratureDecoder, FullCyclesBothWays) {
  QuadratureDecoder d;
  d.reset(ab(0));
  std::int64_t t = 0;
  step(d, 40, &t); // ten cycles forward
  EXPECT_EQ(d.position(), 40);
  EXPECT_EQ(d.levels(), ab(0));
  step(d, -60, &t); // fifteen back
  EXPECT_EQ(d.position(), -20);
  EXPECT_EQ(d.levels(), ab(0));
  EXPECT_EQ(d.counters().missed_edges, 0u);
  EXPECT_EQ(d.counters().duplicates, 0u);
  EXPECT_EQ(d.counters().events, 100u);
}

TEST(QuadratureDecoder, ReversalMidCycle) {
  QuadratureDecoder d;
  d.reset(ab(0));
  std::int64_t t = 0;
  step(d, 6, &t);
  step(d, -9, &t);
  step(d, 2, &t);
  EXPECT_EQ(d.position(), -1);
  EXPECT_EQ(d.counters().missed_edges, 0u);
}

TEST(QuadratureDecoder, ReverseFlagFlipsTheSign) {
  QuadratureAxisConfig reversed;
  reversed.reverse = true;
  QuadratureDecoder d(reversed);
  d.reset(ab(0));
  std::int64_t t = 0;
  step(d, 13, &t);
  EXPECT_EQ(d.position(), -13);
  step(d, -20, &t);
  EXPECT_EQ(d.position(), 7);
}

TEST(QuadratureDecoder, BounceOnOneLineIsHarmless) {
  QuadratureDecoder d;
  d.reset(ab(0));
  // A flickers 0-1-0-1 while B stays low: +1 -1 +1.
  d.on_edge(Line::a, true, 1000);
  d.on_edge(Line::a, false, 1100);
  d.on_edge(Line::a, true, 1200);
  EXPECT_EQ(d.position(), 1);
  EXPECT_EQ(d.counters().missed_edges, 0u);
}

TEST(QuadratureDecoder, DuplicateAfterItsOwnChangeIsOnlyCounted) {
  QuadratureDecoder d;
  d.reset(ab(0));
  std::int64_t t = 0;
  step(d, 5, &t); // the last step was a change of A (state 10)
  EXPECT_EQ(d.levels(), ab(0b10));
  EXPECT_FALSE(d.on_edge(Line::a, true, t + 100)); // same level again
  EXPECT_FALSE(d.on_edge(Line::a, true, t + 200));
  EXPECT_EQ(d.position(), 5);
  EXPECT_EQ(d.counters().duplicates, 2u);
  EXPECT_EQ(d.counters().missed_edges, 0u);
  step(d, 3, &t);
  EXPECT_EQ(d.position(), 8);
}

TEST(QuadratureDecoder, SimultaneousAAndBEdgesAreIllegal) {
  QuadratureDecoder d;
  d.reset(ab(0));
  // 00 -> 10 -> 11 with both edges stamped alike: order unknown, +-2.
  EXPECT_TRUE(d.on_edge(Line::a, true, 5000));
  EXPECT_TRUE(d.on_edge(Line::b, true, 5000)); // takes the first step back
  EXPECT_EQ(d.position(), 0);
  EXPECT_EQ(d.counters().missed_edges, 1u);
  EXPECT_EQ(d.levels(), ab(0b11));
  // Counting goes on from the new state.
  d.on_edge(Line::a, false, 6000); // 11 -> 01 forward
  d.on_edge(Line::b, false, 7000); // 01 -> 00 forward
  EXPECT_EQ(d.position(), 2);
  EXPECT_EQ(d.counters().missed_edges, 1u);
}

TEST(QuadratureDecoder, SameLineTwiceAtOneTimestampIsNotIllegal) {
  QuadratureDecoder d;
  d.reset(ab(0));
  d.on_edge(Line::a, true, 5000);
  d.on_edge(Line::a, false, 5000); // a zero-width pulse on one line: +1 -1
  EXPECT_EQ(d.position(), 0);
  EXPECT_EQ(d.counters().missed_edges, 0u);
}

TEST(QuadratureDecoder, ObservedDoubleChangeCountsWithoutMoving) {
  QuadratureDecoder d;
  d.reset(ab(0b10), 7);
  EXPECT_EQ(d.observe(ab(0b01), 1000), QuadratureStep::illegal);
  EXPECT_EQ(d.position(), 7);
  EXPECT_EQ(d.counters().missed_edges, 1u);
  EXPECT_EQ(d.observe(ab(0b00), 2000), QuadratureStep::forward); // 01 -> 00
  EXPECT_EQ(d.position(), 8);
  EXPECT_EQ(d.counters().recovered, 1u);
}

TEST(QuadratureDecoder, DroppedEdgeInSteadyMotionShowsAsAMissedDuplicate) {
  QuadratureDecoder d;
  d.reset(ab(0));
  // Forward 00 10 11 01 00 with the B rise (10 -> 11) never reported.
  d.on_edge(Line::a, true, 1000);  // 00 -> 10  +1
  d.on_edge(Line::a, false, 3000); // believed 10 -> 00: -1 (truly 11 -> 01, +1)
  d.on_edge(Line::b, false, 4000); // B already low: the lost B edge shows
  EXPECT_EQ(d.counters().duplicates, 1u);
  EXPECT_EQ(d.counters().missed_edges, 1u);
  // A lost event costs the whole cycle and no level reveals it.
  EXPECT_EQ(d.position(), 4 - 4);
  EXPECT_EQ(d.levels(), ab(0));
}

TEST(QuadratureHoming, UngatedIndexHomesOnItsRise) {
  QuadratureDecoder d(homing(1000));
  d.reset(ab(0));
  std::int64_t t = 0;
  step(d, 17, &t);
  EXPECT_FALSE(d.homed());
  EXPECT_TRUE(d.on_edge(Line::index, true, t + 10));
  EXPECT_TRUE(d.homed());
  EXPECT_EQ(d.position(), 1000);
  EXPECT_EQ(d.position_at_last_index(), 17);
  d.on_edge(Line::index, false, t + 20);
  step(d, 5, &t);
  EXPECT_EQ(d.position(), 1005);
  EXPECT_EQ(d.counters().homings, 1u);
}

TEST(QuadratureHoming, FirstIndexOnlyUnlessAskedAgain) {
  QuadratureDecoder d(homing(0));
  d.reset(ab(0));
  std::int64_t t = 0;
  step(d, 10, &t);
  d.on_edge(Line::index, true, t += 10);
  d.on_edge(Line::index, false, t += 10);
  step(d, 8, &t);
  d.on_edge(Line::index, true, t += 10); // a second pulse (next shaft turn)
  d.on_edge(Line::index, false, t += 10);
  EXPECT_EQ(d.position(), 8);
  EXPECT_EQ(d.counters().index_pulses, 2u);
  EXPECT_EQ(d.counters().homings, 1u);

  d.request_home();
  EXPECT_FALSE(d.homed());
  d.on_edge(Line::index, true, t += 10);
  EXPECT_TRUE(d.homed());
  EXPECT_EQ(d.position(), 0);
}

TEST(QuadratureHoming, EveryIndexWhenConfigured) {
  QuadratureDecoder d(homing(0, IndexGate::any, true));
  d.reset(ab(0));
  std::int64_t t = 0;
  for (int turn = 0; turn < 3; ++turn) {
    step(d, 9, &t);
    d.on_edge(Line::index, true, t += 10);
    d.on_edge(Line::index, false, t += 10);
    EXPECT_EQ(d.position(), 0);
  }
  EXPECT_EQ(d.counters().homings, 3u);
}

TEST(QuadratureHoming, GatedIndexHomesAtTheSameCountFromEitherSide) {
  // The index is high during one quarter (state 11) and its edges come in
  // either order relative to the A/B edge that enters that quarter.
  for (const bool index_first : {false, true}) {
    for (const int direction : {+1, -1}) {
      SCOPED_TRACE(testing::Message()
                   << "index first " << index_first << " direction " << direction);
      QuadratureDecoder d(homing(500, IndexGate::ab11));
      // Start two quarters away from 11 (state 00 is opposite 11 in the
      // cycle) and step towards it: forward 00 -> 10 -> 11, backward 00 ->
      // 01 -> 11.
      d.reset(ab(0));
      std::int64_t t = 0;
      step(d, direction, &t);
      if (index_first) {
        d.on_edge(Line::index, true, t + 1000); // gate not open yet
        EXPECT_FALSE(d.homed());
        step(d, direction, &t);
      } else {
        step(d, direction, &t);
        EXPECT_FALSE(d.homed());
        d.on_edge(Line::index, true, t);
      }
      EXPECT_TRUE(d.homed());
      EXPECT_EQ(d.position(), 500);
      EXPECT_EQ(d.levels().a && d.levels().b, true);
    }
  }
}

TEST(QuadratureHoming, IndexAlreadyHighAtResetDoesNotHome) {
  QuadratureDecoder d(homing(50));
  d.reset(AxisLevels{false, false, true}, 3);
  EXPECT_FALSE(d.homed());
  EXPECT_EQ(d.position(), 3);
  d.on_edge(Line::index, false, 1000);
  d.on_edge(Line::index, true, 2000);
  EXPECT_TRUE(d.homed());
  EXPECT_EQ(d.position(), 50);
}

TEST(QuadratureHoming, WithoutCountsAtIndexPulsesAreOnlyCounted) {
  QuadratureDecoder d;
  d.reset(ab(0));
  std::int64_t t = 0;
  step(d, 4, &t);
  EXPECT_FALSE(d.on_edge(Line::index, true, t + 1));
  EXPECT_EQ(d.position(), 4);
  EXPECT_FALSE(d.homed());
  EXPECT_EQ(d.counters().index_pulses, 1u);
}

TEST(QuadratureHoming, ResyncKeepsTheCountButForgetsHoming) {
  QuadratureDecoder d(homing(10));
  d.reset(ab(0));
  d.on_edge(Line::index, true, 1);
  ASSERT_TRUE(d.homed());
  d.resync(ab(0b11));
  EXPECT_FALSE(d.homed());
  EXPECT_EQ(d.position(), 10);
  EXPECT_EQ(d.levels(), ab(0b11));
}

} // namespace
} // namespace camhead::hal::lens::gpio
