// The simulated twin of the GPIO quadrature encoder: a position trajectory
// per axis (counts against time) becomes the A/B/index edge sequence a real
// encoder would put on the wire, optionally with the faults real wiring and a
// busy kernel produce. SimulatedQuadrature is an EdgeSource, so the twin is a
// QuadratureEncoder like the hardware one: same decoders, same coalescing,
// same reconnect handling (quadrature_encoder.h); only the source differs.
//
// Physics of the model: the count is floor(position); its lines follow the
// Gray code 00, 10, 11, 01 (AB) by count mod 4, so counting up is A leading
// B, the decoder's forward direction. The index line is high while the count
// equals index_count: an index gated to one quarter of a cycle, the
// commonest kind, whose A/B state is quadrature_levels(index_count).
//
// Like the real encoder, the twin's counts start at 0 wherever the trajectory
// starts; the index (counts_at_index) makes them absolute.
//
// Thread safety: none; the lens thread owns it through its encoder. The test
// controls (set_present) belong to that thread too.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camhead/hal/lens/gpio/edge_source.h"
#include "camhead/hal/lens/gpio/quadrature_decoder.h"
#include "camhead/hal/lens/gpio/quadrature_encoder.h"

namespace camhead::hal::lens::gpio {

// Position in counts at a time, relative to trajectory time 0. Positions
// between keyframes are straight lines; before the first keyframe the
// position is the first's, after the last it holds.
struct TrajectoryPoint {
  std::int64_t t_ns = 0;
  double counts = 0.0;
};

// Faults on one axis' A/B edges, by ordinal: 0 is the first A/B edge the
// trajectory makes, in time order (index edges are not numbered).
struct EdgeFaults {
  // Edge k is reported with the timestamp of edge k+1: two lines change in one
  // tick, as when the encoder outruns a sampling reader. The decoder counts a
  // missed edge and the two steps are lost.
  std::vector<std::uint64_t> merged;
  // Edge k is never reported (a full kernel queue); the line still changes.
  std::vector<std::uint64_t> dropped;
  // After edge k the line flips back and forth once more, bounce_ns and
  // 2 * bounce_ns later: two extra events of zero net motion.
  std::vector<std::uint64_t> bounced;
  // Edge k is reported a second time, bounce_ns later: the same level twice.
  std::vector<std::uint64_t> duplicated;
  // Faults that would not end before the next edge (bounce or copy later than
  // a third of the gap to it) are left out.
  std::int64_t bounce_ns = 100;
};

struct SimulatedQuadratureAxis {
  std::vector<TrajectoryPoint> trajectory;
  std::optional<std::int32_t> index_count; // the count in which the index is high
  EdgeFaults faults;
  QuadratureAxisConfig decoder; // how the twin's decoder reads this axis
};

enum class SimClock : std::uint8_t {
  // Trajectory time 0 is the first open(), on CLOCK_MONOTONIC; waits sleep.
  real_time,
  // Time starts at 0 and only waits move it, instantly: deterministic tests
  // that never sleep.
  virtual_time,
};

struct SimulatedQuadratureConfig {
  std::optional<SimulatedQuadratureAxis> focus, iris, zoom;
  SimClock clock = SimClock::real_time;
  // How long after the first pending edge a wait returns, as a real reader
  // wakes a little after its interrupt: the edges in that window arrive as
  // one batch (one reading).
  std::chrono::nanoseconds wake_latency{100'000};
  std::chrono::milliseconds reopen_interval{1000};
};

// The levels of an axis' lines when its count is `count`.
[[nodiscard]] AxisLevels quadrature_levels(std::int64_t count,
                                           std::optional<std::int32_t> index_count);

// Every edge `motion` produces, faults applied, tagged with `axis`, times
// relative to trajectory time 0, ordered by time (stable: an edge keeps its
// place before an equal-time successor).
[[nodiscard]] std::vector<EdgeEvent> quadrature_edges(LensAxis axis,
                                                      const SimulatedQuadratureAxis &motion);

class SimulatedQuadrature final : public EdgeSource {
public:
  explicit SimulatedQuadrature(const SimulatedQuadratureConfig &config);

  [[nodiscard]] std::string name() const override { return "gpio sim"; }
  [[nodiscard]] AxisSet axes() const override { return axes_; }
  [[nodiscard]] bool open(std::string &error) override;
  void close() override { open_ = false; }
  [[nodiscard]] bool read_levels(AllLevels &levels, std::int64_t &t_ns,
                                 std::string &error) override;
  [[nodiscard]] bool wait_edges(std::chrono::milliseconds timeout, std::vector<EdgeEvent> &out,
                                std::string &error) override;
  [[nodiscard]] std::int64_t now_ns() const override;
  void sleep_for(std::chrono::nanoseconds duration) override;

  // Unplugs (false) or replugs (true) the simulated chip. While unplugged,
  // waits and reads fail as a removed chip's do and open() is refused; edges
  // in the gap are never delivered.
  void set_present(bool present) { present_ = present; }

private:
  // Applies physical level changes up to `t_ns` to truth_levels_.
  void advance_truth(std::int64_t t_ns);

  SimClock clock_;
  std::chrono::nanoseconds wake_latency_;
  AxisSet axes_{};
  std::vector<EdgeEvent> reported_; // what the kernel would deliver
  std::vector<EdgeEvent> physical_; // what the lines actually do
  std::size_t next_reported_ = 0, next_physical_ = 0;
  AllLevels truth_levels_{};
  std::int64_t t0_ns_ = 0;  // absolute time of trajectory time 0
  std::int64_t now_ns_ = 0; // virtual clock (absolute)
  bool started_ = false, open_ = false, present_ = true;
};

// The twin as a LensEncoder: SimulatedQuadrature + QuadratureEncoder.
[[nodiscard]] std::unique_ptr<QuadratureEncoder>
open_simulated_quadrature(const SimulatedQuadratureConfig &config);

} // namespace camhead::hal::lens::gpio
