// The simulated twin: trajectories become the edges a real encoder makes, and
// the twin, used only through the LensEncoder interface, reports what the
// trajectory did, including homing, injected faults and an unplug.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "camhead/hal/lens/gpio/quadrature_decoder.h"
#include "camhead/hal/lens/gpio/simulated_quadrature.h"
#include "camhead/hal/lens/lens_encoder.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens::gpio {
namespace {

using namespace std::chrono_literals;

constexpr std::int64_t kMs = 1'000'000;

// Decodes edges with one fresh decoder per axis, from the start levels.
QuadratureDecoder decode(const std::vector<EdgeEvent> &edges, AxisLevels start = {},
                         QuadratureAxisConfig config = {}) {
  QuadratureDecoder d(config);
  d.reset(start);
  for (const EdgeEvent &e : edges) {
    d.on_edge(e.line, e.level, e.t_ns);
  }
  return d;
}

// Polls `encoder` through the interface until `until_ns` of virtual time.
std::vector<EncoderReading> run(LensEncoder &encoder, SimulatedQuadrature *clock,
                                std::int64_t until_ns) {
  std::vector<EncoderReading> out;
  while (clock->now_ns() < until_ns) {
    encoder.poll(10ms, out);
  }
  return out;
}

SimulatedQuadratureAxis ramp(std::vector<TrajectoryPoint> points) {
  SimulatedQuadratureAxis axis;
  axis.trajectory = std::move(points);
  return axis;
}

TEST(SimulatedQuadrature, LevelsFollowTheGrayCode) {
  // 00 10 11 01, repeating, negative counts included.
  const unsigned expected[8] = {0b00, 0b10, 0b11, 0b01, 0b00, 0b10, 0b11, 0b01};
  for (int c = -8; c < 8; ++c) {
    const AxisLevels l = quadrature_levels(c, 3);
    const unsigned state = (l.a ? 2u : 0u) | (l.b ? 1u : 0u);
    EXPECT_EQ(state, expected[(c + 8) % 8]) << "count " << c;
    EXPECT_EQ(l.index, c == 3) << "count " << c;
  }
}

TEST(SimulatedQuadrature, RampUpAndBackMakesOneEdgePerCount) {
  const auto axis = ramp({{0, 0.0}, {10'000, 10.0}, {16'000, 4.0}});
  const std::vector<EdgeEvent> edges = quadrature_edges(LensAxis::zoom, axis);
  ASSERT_EQ(edges.size(), 16u); // 10 up, 6 down
  for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
    EXPECT_LE(edges[i].t_ns, edges[i + 1].t_ns);
    EXPECT_EQ(edges[i].axis, LensAxis::zoom);
  }
  EXPECT_EQ(edges.front().t_ns, 1000); // count 1 reached after 1 us
  EXPECT_EQ(edges.front().line, QuadratureLine::a);
  const QuadratureDecoder d = decode(edges);
  EXPECT_EQ(d.position(), 4);
  EXPECT_EQ(d.counters().missed_edges, 0u);
}

TEST(SimulatedQuadrature, GatedIndexEdgesSurroundItsQuarter) {
  auto axis = ramp({{0, 0.0}, {10'000, 10.0}});
  axis.index_count = 6;
  const std::vector<EdgeEvent> edges = quadrature_edges(LensAxis::focus, axis);
  std::vector<EdgeEvent> index;
  std::copy_if(edges.begin(), edges.end(), std::back_inserter(index),
               [](const EdgeEvent &e) { return e.line == QuadratureLine::index; });
  ASSERT_EQ(index.size(), 2u);
  EXPECT_EQ(index[0], (EdgeEvent{6000, LensAxis::focus, QuadratureLine::index, true}));
  EXPECT_EQ(index[1], (EdgeEvent{7000, LensAxis::focus, QuadratureLine::index, false}));
}

TEST(SimulatedQuadrature, FaultsShapeTheEdgeStream) {
  auto axis = ramp({{0, 0.0}, {100'000, 100.0}}); // 1 count per us
  axis.faults.merged = {10};
  axis.faults.dropped = {20};
  axis.faults.bounced = {30};
  axis.faults.duplicated = {40};
  const std::vector<EdgeEvent> edges = quadrature_edges(LensAxis::focus, axis);
  EXPECT_EQ(edges.size(), 100u - 1 + 2 + 1);
  // Edge 10 (count 10 -> 11, at 11 us) now carries edge 11's stamp.
  EXPECT_EQ(std::count_if(edges.begin(), edges.end(),
                          [](const EdgeEvent &e) { return e.t_ns == 12'000; }),
            2);
  const QuadratureDecoder d = decode(edges);
  // merged: -2 and one missed; dropped: -4 and one missed (see the decoder).
  EXPECT_EQ(d.position(), 100 - 2 - 4);
  EXPECT_EQ(d.counters().missed_edges, 2u);
  EXPECT_EQ(d.counters().duplicates, 2u); // the copy, and the edge after the drop
}

TEST(SimulatedTwin, ReportsTheTrajectoryThroughTheInterface) {
  SimulatedQuadratureConfig config;
  config.clock = SimClock::virtual_time;
  config.focus = ramp({{0, 0.0}, {40 * kMs, 400.0}, {60 * kMs, 400.0}, {80 * kMs, 100.0}});
  config.zoom = ramp({{0, 0.5}, {50 * kMs, -60.5}});
  auto source = std::make_unique<SimulatedQuadrature>(config);
  SimulatedQuadrature *sim = source.get();
  QuadratureEncoderOptions motion_only;
  motion_only.still_interval = 0ms; // StillEncoderIsReportedStill covers those
  QuadratureEncoder twin(std::move(source), {}, motion_only);
  LensEncoder &encoder = twin;

  EXPECT_EQ(encoder.name(), "gpio sim");
  const std::vector<EncoderReading> readings = run(encoder, sim, 100 * kMs);
  ASSERT_GE(readings.size(), 2u);
  // The connect reading: both axes, at their start, at time 0.
  EncoderReading first;
  first.focus = 0;
  first.zoom = 0;
  EXPECT_EQ(readings.front(), first);
  for (std::size_t i = 1; i < readings.size(); ++i) {
    EXPECT_LE(readings[i - 1].t_ns, readings[i].t_ns);
    EXPECT_FALSE(readings[i].iris.has_value());
  }
  EXPECT_EQ(readings.back().focus, 100);
  EXPECT_EQ(readings.back().zoom, -61);
  // The last edge of focus: count 101 -> 100 on the way down.
  EXPECT_EQ(readings.back().t_ns, 60 * kMs + (400 - 101) * 20 * kMs / 300);

  const EncoderStatus s = encoder.status();
  EXPECT_TRUE(s.connected);
  EXPECT_EQ(s.readings, readings.size());
  EXPECT_EQ(s.missed_edges, 0u);
  EXPECT_EQ(s.lost, 0u);
  EXPECT_EQ(s.detail, "gpio sim: connected; focus 100, zoom -61");
}

TEST(SimulatedTwin, CoalescesABurstIntoFewReadings) {
  SimulatedQuadratureConfig config;
  config.clock = SimClock::virtual_time;
  config.wake_latency = 100us;
  config.focus = ramp({{1 * kMs, 0.0}, {2 * kMs, 1000.0}}); // 1 MHz of edges for 1 ms
  auto source = std::make_unique<SimulatedQuadrature>(config);
  SimulatedQuadrature *sim = source.get();
  QuadratureEncoder twin(std::move(source), {});
  const std::vector<EncoderReading> readings = run(twin, sim, 5 * kMs);
  // One connect reading, then one per wake-up: 100 us of edges each.
  EXPECT_GE(readings.size(), 1u + 9u);
  EXPECT_LE(readings.size(), 1u + 11u);
  EXPECT_EQ(readings.back().focus, 1000);
  EXPECT_EQ(readings.back().t_ns, 2 * kMs);
}

TEST(SimulatedTwin, HomesOnTheGatedIndex) {
  SimulatedQuadratureConfig config;
  config.clock = SimClock::virtual_time;
  SimulatedQuadratureAxis focus = ramp({{0, 20.0}, {10 * kMs, 120.0}, {20 * kMs, 40.0}});
  focus.index_count = 50;
  const AxisLevels gate = quadrature_levels(50, std::nullopt);
  focus.decoder.counts_at_index = 50;
  focus.decoder.index_gate = gate.a ? (gate.b ? IndexGate::ab11 : IndexGate::ab10)
                                    : (gate.b ? IndexGate::ab01 : IndexGate::ab00);
  config.focus = focus;
  auto source = std::make_unique<SimulatedQuadrature>(config);
  SimulatedQuadrature *sim = source.get();
  QuadratureEncoder twin(std::move(source), {config.focus->decoder});
  EXPECT_FALSE(twin.homed(LensAxis::focus));
  const std::vector<EncoderReading> readings = run(twin, sim, 30 * kMs);
  EXPECT_TRUE(twin.homed(LensAxis::focus));
  // Counts start at 0 where the trajectory starts (20); homing makes them
  // the trajectory's own counts.
  EXPECT_EQ(readings.back().focus, 40);
  EXPECT_EQ(twin.decoder(LensAxis::focus).counters().index_pulses, 2u); // up, then down
  EXPECT_EQ(twin.decoder(LensAxis::focus).counters().homings, 1u);
  EXPECT_EQ(twin.status().detail, "gpio sim: connected; focus 40 homed");
}

TEST(SimulatedTwin, CountsMergedEdgesAsMissed) {
  SimulatedQuadratureConfig config;
  config.clock = SimClock::virtual_time;
  SimulatedQuadratureAxis iris = ramp({{0, 0.0}, {1 * kMs, 200.0}});
  iris.faults.merged = {20, 90, 150};
  config.iris = iris;
  auto source = std::make_unique<SimulatedQuadrature>(config);
  SimulatedQuadrature *sim = source.get();
  QuadratureEncoder twin(std::move(source), {});
  const std::vector<EncoderReading> readings = run(twin, sim, 5 * kMs);
  EXPECT_EQ(readings.back().iris, 200 - 3 * 2);
  EXPECT_EQ(twin.status().missed_edges, 3u);
}

TEST(SimulatedTwin, IdleRereadRecoversADroppedLastEdge) {
  SimulatedQuadratureConfig config;
  config.clock = SimClock::virtual_time;
  SimulatedQuadratureAxis zoom = ramp({{0, 0.0}, {1 * kMs, 37.0}});
  zoom.faults.dropped = {36}; // the very last edge
  config.zoom = zoom;
  auto source = std::make_unique<SimulatedQuadrature>(config);
  SimulatedQuadrature *sim = source.get();
  QuadratureEncoder twin(std::move(source), {});
  const std::vector<EncoderReading> readings = run(twin, sim, 5 * kMs);
  EXPECT_EQ(readings.back().zoom, 37);
  EXPECT_EQ(twin.status().lost, 1u);
  EXPECT_EQ(twin.status().missed_edges, 0u);
}

TEST(SimulatedTwin, SurvivesAnUnplugAndComesBackUnhomed) {
  SimulatedQuadratureConfig config;
  config.clock = SimClock::virtual_time;
  config.reopen_interval = 500ms;
  SimulatedQuadratureAxis focus = ramp({{0, 0.0}, {3000 * kMs, 3000.0}}); // 1 count per ms
  focus.index_count = 10;
  focus.decoder.counts_at_index = 10;
  config.focus = focus;
  auto source = std::make_unique<SimulatedQuadrature>(config);
  SimulatedQuadrature *sim = source.get();
  QuadratureEncoderOptions options;
  options.reopen_interval = config.reopen_interval;
  QuadratureEncoder twin(std::move(source), {config.focus->decoder}, options);

  std::vector<EncoderReading> out = run(twin, sim, 100 * kMs);
  ASSERT_TRUE(twin.homed(LensAxis::focus));
  EXPECT_NEAR(*out.back().focus, 100, 1);

  sim->set_present(false);
  EXPECT_NO_THROW(twin.poll(10ms, out));
  EncoderStatus s = twin.status();
  EXPECT_FALSE(s.connected);
  EXPECT_NE(s.detail.find("gpio sim"), std::string::npos) << s.detail;
  EXPECT_NE(s.detail.find("simulated unplug"), std::string::npos) << s.detail;
  EXPECT_NE(s.detail.find("reopening every 500 ms"), std::string::npos) << s.detail;

  // Polls while unplugged wait out their timeout, never throw.
  out.clear();
  const std::int64_t unplugged_at = sim->now_ns();
  while (sim->now_ns() < unplugged_at + 1000 * kMs) {
    EXPECT_NO_THROW(twin.poll(10ms, out));
  }
  EXPECT_TRUE(out.empty());
  EXPECT_FALSE(twin.status().connected);

  sim->set_present(true);
  out = run(twin, sim, sim->now_ns() + 600 * kMs);
  s = twin.status();
  EXPECT_TRUE(s.connected);
  EXPECT_EQ(s.reconnects, 1u);
  EXPECT_FALSE(twin.homed(LensAxis::focus)); // edges were lost in the gap
  EXPECT_NE(s.detail.find("not homed"), std::string::npos) << s.detail;
  // An axis that homes on its index is withheld until it homes again: its
  // count carries on from where it was, the ~1 s gap missing from it.
  EXPECT_TRUE(out.empty()) << "unhomed counts must not reach the lens profile";
  const std::int64_t true_count = sim->now_ns() / kMs;
  const std::int32_t position = twin.decoder(LensAxis::focus).position();
  EXPECT_LT(position, true_count - 900);
  EXPECT_GT(position, 0);
}

// Before its first index pulse an axis that homes on the index delivers
// nothing; from the pulse on, absolute counts.
TEST(SimulatedTwin, WithholdsAnAxisUntilItHomes) {
  SimulatedQuadratureConfig config;
  config.clock = SimClock::virtual_time;
  SimulatedQuadratureAxis focus = ramp({{0, 0.0}, {100 * kMs, 100.0}});
  focus.index_count = 50;
  focus.decoder.counts_at_index = 5000;
  config.focus = focus;
  auto source = std::make_unique<SimulatedQuadrature>(config);
  SimulatedQuadrature *sim = source.get();
  QuadratureEncoder twin(std::move(source), {config.focus->decoder});

  std::vector<EncoderReading> out = run(twin, sim, 40 * kMs);
  EXPECT_TRUE(out.empty());
  out = run(twin, sim, 100 * kMs);
  ASSERT_FALSE(out.empty());
  EXPECT_TRUE(twin.homed(LensAxis::focus));
  for (const EncoderReading &r : out)
    EXPECT_GE(*r.focus, 5000) << "only counts after homing";
  EXPECT_NEAR(*out.back().focus, 5050, 1);
}

// No edges is no news: a still encoder is reported still, at the instants its
// lines were re-read, so that downstream the lens is not taken for lost.
TEST(SimulatedTwin, StillEncoderIsReportedStill) {
  SimulatedQuadratureConfig config;
  config.clock = SimClock::virtual_time;
  config.focus = ramp({{0, 0.0}, {10 * kMs, 50.0}});
  auto source = std::make_unique<SimulatedQuadrature>(config);
  SimulatedQuadrature *sim = source.get();
  QuadratureEncoder twin(std::move(source), {});
  const std::vector<EncoderReading> readings = run(twin, sim, 200 * kMs);
  std::vector<std::int64_t> still;
  for (const EncoderReading &r : readings)
    if (r.t_ns > 10 * kMs) {
      EXPECT_EQ(r.focus, 50);
      still.push_back(r.t_ns);
    }
  ASSERT_GE(still.size(), 5u) << "190 ms of stillness at one reading per 20 ms";
  for (std::size_t i = 1; i < still.size(); ++i)
    EXPECT_GE(still[i] - still[i - 1], 20 * kMs);
  EXPECT_GE(still.back(), 170 * kMs);
}

TEST(SimulatedTwin, RealTimeClockSmoke) {
  SimulatedQuadratureConfig config; // real time: this test sleeps ~20 ms
  config.focus = ramp({{0, 0.0}, {20 * kMs, 20.0}});
  auto twin = open_simulated_quadrature(config);
  std::vector<EncoderReading> out;
  const auto start = std::chrono::steady_clock::now();
  while ((out.empty() || out.back().focus != 20) && std::chrono::steady_clock::now() - start < 2s) {
    twin->poll(5ms, out);
  }
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.back().focus, 20);
  // Paced by the clock: the last edge is 20 ms into the trajectory.
  EXPECT_GE(std::chrono::steady_clock::now() - start, 19ms);
  EXPECT_TRUE(twin->status().connected);
}

TEST(SimulatedTwin, NeedsAnAxis) {
  EXPECT_THROW((void)open_simulated_quadrature(SimulatedQuadratureConfig{}), std::invalid_argument);
}

} // namespace
} // namespace camhead::hal::lens::gpio
