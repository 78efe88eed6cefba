// A recorded 1 MHz-equivalent edge burst (tests/assets/quadrature_burst_1mhz.csv,
// made by make_quadrature_burst.py in this folder, whose docstring has the
// plan): the decoder must count it exactly, through the encoder too, and the
// simulated twin must reproduce it from a trajectory. The decode rate is
// printed for information; it never decides a pass.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "camhead/hal/lens/gpio/edge_source.h"
#include "camhead/hal/lens/gpio/quadrature_decoder.h"
#include "camhead/hal/lens/gpio/quadrature_encoder.h"
#include "camhead/hal/lens/gpio/simulated_quadrature.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens::gpio {
namespace {

using namespace std::chrono_literals;

const std::string kPath =
    std::string(CAMHEAD_SOURCE_DIR) + "/tests/assets/quadrature_burst_1mhz.csv";

// The plan's arithmetic (make_quadrature_burst.py), written out once more so
// that the test does not only trust the file's own header.
constexpr std::int32_t kFocusCount = 2000 - 1200 + 500 - 2 * 4 + 2 * 2; // 1296
constexpr std::uint64_t kFocusMissed = 6, kFocusDuplicates = 2;
constexpr std::int32_t kZoomCount = -40 + 15;
constexpr std::size_t kEvents = 3700 + 2 * 1 + 2 * 2 + 40 + 15;

struct Recording {
  std::vector<EdgeEvent> events;
  std::map<std::string, long long> expect; // from the "# expect k=v ..." line
};

Recording load(const std::string &path) {
  std::ifstream in(path);
  if (!in) {
    throw std::runtime_error(path + ": cannot open");
  }
  Recording r;
  std::string row;
  for (int line = 1; std::getline(in, row); ++line) {
    const std::string where = path + ":" + std::to_string(line) + ": ";
    if (row.rfind("# expect ", 0) == 0) {
      std::istringstream fields(row.substr(9));
      for (std::string kv; fields >> kv;) {
        const auto eq = kv.find('=');
        r.expect[kv.substr(0, eq)] = std::stoll(kv.substr(eq + 1));
      }
      continue;
    }
    if (row.empty() || row[0] == '#' || row.rfind("t_ns,", 0) == 0) {
      continue;
    }
    std::istringstream cells(row);
    std::string t, axis, which, level;
    if (!std::getline(cells, t, ',') || !std::getline(cells, axis, ',') ||
        !std::getline(cells, which, ',') || !std::getline(cells, level, ',')) {
      throw std::runtime_error(where + "expected t_ns,axis,line,level");
    }
    EdgeEvent e;
    e.t_ns = std::stoll(t);
    e.axis = axis == "focus" ? LensAxis::focus : axis == "iris" ? LensAxis::iris : LensAxis::zoom;
    e.line = which == "a"   ? QuadratureLine::a
             : which == "b" ? QuadratureLine::b
                            : QuadratureLine::index;
    e.level = level == "1";
    r.events.push_back(e);
  }
  return r;
}

std::array<QuadratureDecoder, kLensAxisCount> decode(const std::vector<EdgeEvent> &events) {
  std::array<QuadratureDecoder, kLensAxisCount> d{};
  for (const EdgeEvent &e : events) {
    d[static_cast<std::size_t>(e.axis)].on_edge(e.line, e.level, e.t_ns);
  }
  return d;
}

// Plays the recording back as an edge source, `batch` events per wait, on a
// virtual clock; its line levels are the last ones it reported.
class ReplaySource final : public EdgeSource {
public:
  ReplaySource(std::vector<EdgeEvent> events, std::size_t batch)
      : events_(std::move(events)), batch_(batch) {}
  std::string name() const override { return "gpio replay"; }
  AxisSet axes() const override { return {true, false, true}; }
  bool open(std::string &) override { return true; }
  void close() override {}
  bool read_levels(AllLevels &levels, std::int64_t &t_ns, std::string &) override {
    levels = levels_;
    t_ns = now_;
    return true;
  }
  bool wait_edges(std::chrono::milliseconds timeout, std::vector<EdgeEvent> &out,
                  std::string &) override {
    if (next_ == events_.size()) {
      now_ += std::chrono::nanoseconds(timeout).count();
      return true;
    }
    for (std::size_t n = 0; n < batch_ && next_ < events_.size(); ++n) {
      const EdgeEvent &e = events_[next_++];
      AxisLevels &l = levels_[static_cast<std::size_t>(e.axis)];
      (e.line == QuadratureLine::a ? l.a : e.line == QuadratureLine::b ? l.b : l.index) = e.level;
      now_ = e.t_ns;
      out.push_back(e);
    }
    return true;
  }
  std::int64_t now_ns() const override { return now_; }

private:
  std::vector<EdgeEvent> events_;
  std::size_t batch_, next_ = 0;
  AllLevels levels_{};
  std::int64_t now_ = 0;
};

TEST(QuadratureRecording, IsSmallAndIsABurst) {
  EXPECT_LT(std::filesystem::file_size(kPath), 1u << 20);
  const Recording r = load(kPath);
  ASSERT_EQ(r.events.size(), kEvents);
  EXPECT_EQ(r.expect.at("events"), static_cast<long long>(kEvents));
  // 3.7 ms of focus edges 1 us apart: a 1 MHz edge rate.
  EXPECT_EQ(r.events.back().t_ns, 3'700'000);
  for (std::size_t i = 1; i < r.events.size(); ++i) {
    ASSERT_LE(r.events[i - 1].t_ns, r.events[i].t_ns) << "event " << i;
  }
}

TEST(QuadratureRecording, DecodesExactly) {
  const Recording r = load(kPath);
  // The file's header agrees with the plan as written in this test.
  EXPECT_EQ(r.expect.at("focus_count"), kFocusCount);
  EXPECT_EQ(r.expect.at("focus_missed"), static_cast<long long>(kFocusMissed));
  EXPECT_EQ(r.expect.at("focus_duplicates"), static_cast<long long>(kFocusDuplicates));
  EXPECT_EQ(r.expect.at("zoom_count"), kZoomCount);
  EXPECT_EQ(r.expect.at("zoom_missed"), 0);

  const auto d = decode(r.events);
  const QuadratureDecoder &focus = d[static_cast<std::size_t>(LensAxis::focus)];
  const QuadratureDecoder &zoom = d[static_cast<std::size_t>(LensAxis::zoom)];
  EXPECT_EQ(focus.position(), kFocusCount);
  EXPECT_EQ(focus.counters().missed_edges, kFocusMissed);
  EXPECT_EQ(focus.counters().duplicates, kFocusDuplicates);
  EXPECT_EQ(zoom.position(), kZoomCount);
  EXPECT_EQ(zoom.counters().missed_edges, 0u);

  // Information only: how much faster than real time the decoder runs.
  const std::int64_t burst_ns = r.events.back().t_ns - r.events.front().t_ns;
  std::size_t edges = 0;
  std::int64_t sink = 0;
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = std::chrono::steady_clock::duration::zero();
  do {
    for (int rep = 0; rep < 20; ++rep) {
      sink += decode(r.events)[0].position();
      edges += r.events.size();
    }
    elapsed = std::chrono::steady_clock::now() - start;
  } while (elapsed < 200ms);
  const double seconds = std::chrono::duration<double>(elapsed).count();
  const double rate = static_cast<double>(edges) / seconds;
  std::printf("[   INFO   ] decode rate %.3g edges/s (%.2f ns/edge, %.0fx real time for this "
              "burst; checksum %lld)\n",
              rate, 1e9 / rate, rate / (static_cast<double>(r.events.size()) * 1e9 / burst_ns),
              static_cast<long long>(sink % 1000));
  RecordProperty("decode_rate_edges_per_s", std::to_string(static_cast<long long>(rate)));
}

TEST(QuadratureRecording, DecodesExactlyThroughTheEncoder) {
  const Recording r = load(kPath);
  QuadratureEncoder encoder(std::make_unique<ReplaySource>(r.events, 64), {});
  std::vector<EncoderReading> out;
  for (std::size_t polls = 0; polls < r.events.size() / 64 + 3; ++polls) {
    encoder.poll(10ms, out);
  }
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.back().focus, kFocusCount);
  EXPECT_EQ(out.back().zoom, kZoomCount);
  EXPECT_FALSE(out.back().iris.has_value());
  EXPECT_EQ(out.back().t_ns, 3'700'000);
  EXPECT_LE(out.size(), r.events.size() / 64 + 2); // at most one per batch
  const EncoderStatus s = encoder.status();
  EXPECT_EQ(s.missed_edges, kFocusMissed);
  EXPECT_EQ(s.lost, 0u); // the idle re-read found nothing to recover
}

TEST(QuadratureRecording, TheTwinReproducesIt) {
  // The same plan as a trajectory: 1 count per us, turning half a count past
  // the last edge of each phase.
  SimulatedQuadratureAxis focus;
  focus.trajectory = {{0, 0.0}, {2'000'500, 2000.5}, {3'200'500, 800.5}, {3'700'500, 1300.5}};
  focus.faults.merged = {500, 1000, 1500, 2300, 2700, 3500};
  focus.faults.duplicated = {100, 2500};
  focus.faults.bounced = {200, 3000};
  focus.faults.bounce_ns = 100;
  SimulatedQuadratureAxis zoom;
  zoom.trajectory = {{250, 0.5}, {800'250, -39.5}, {1'100'250, -24.5}};

  std::vector<EdgeEvent> twin = quadrature_edges(LensAxis::focus, focus);
  const std::vector<EdgeEvent> z = quadrature_edges(LensAxis::zoom, zoom);
  twin.insert(twin.end(), z.begin(), z.end());
  std::stable_sort(twin.begin(), twin.end(),
                   [](const EdgeEvent &x, const EdgeEvent &y) { return x.t_ns < y.t_ns; });

  const Recording r = load(kPath);
  ASSERT_EQ(twin.size(), r.events.size());
  for (std::size_t i = 0; i < twin.size(); ++i) {
    ASSERT_EQ(twin[i], r.events[i]) << "event " << i << " at " << r.events[i].t_ns << " ns";
  }
}

} // namespace
} // namespace camhead::hal::lens::gpio
