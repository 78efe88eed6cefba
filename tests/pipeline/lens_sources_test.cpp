// The lens chain of a board, end to end: every kind of simulated source opens
// from a board file, delivers the trace it follows through its own device
// code (USB reports, quadrature edges, trace replay), and the board's profile
// turns that into the same lens state.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "camhead/hal/lens/monotonic_clock.h"
#include "config/board.h"
#include "config/lens_sources.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class LensSources : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("camhead_lens_sources_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            std::to_string(hal::lens::monotonic_ns()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A fast focus pull: 13200 -> 2100 counts in 0.3 s, then still for 2.7 s
  // (longer than the test runs: the simulated USB board loops its trace).
  fs::path write_trace() {
    std::ofstream out(dir_ / "pull.csv");
    out << "# camhead lens trace v1\nt_s,focus,iris,zoom,focus_m,f_stop,focal_mm\n";
    for (int i = 0; i <= 300; ++i) {
      const int focus = i <= 30 ? 13200 - (13200 - 2100) * i / 30 : 2100;
      out << i * 0.01 << "," << focus << ",1900,0,,,\n";
    }
    return dir_ / "pull.csv";
  }

  fs::path dir_;
};

TEST_F(LensSources, EverySimulatedSourceFollowsItsTraceToTheSameLensState) {
  write_trace();
  const std::string profile =
      (fs::path(CAMHEAD_SOURCE_DIR) / "scenes" / "lenses" / "example_35mm.json").string();
  const Board board = parse_board(R"({
      "format": "camhead-board", "version": 1, "name": "three twins",
      "lens": {"profile": ")" + profile +
                                      R"(", "sources": [
        {"name": "replay", "type": "trace", "file": "pull.csv", "loop": false},
        {"name": "usb", "type": "usb", "vendor_id": "1209", "product_id": "0001",
         "simulate": "pull.csv"},
        {"name": "gpio", "type": "gpio", "chip": "sim",
         "axes": {"focus": {"a": 0, "b": 1, "index": 2, "counts_at_index": 8000}},
         "simulate": "pull.csv"}]}})",
                                  dir_ / "board.json");
  std::vector<LensChannel> channels = open_lens_channels(board);
  ASSERT_EQ(channels.size(), 3u);

  // Real time: the sources are live. Past the end of the pull everything is
  // still, so the outcome does not depend on how fast this machine is.
  const auto until = std::chrono::steady_clock::now() + 1200ms;
  while (std::chrono::steady_clock::now() < until)
    for (LensChannel &channel : channels)
      channel.pump(5ms);

  const std::int64_t now = hal::lens::monotonic_ns();
  for (const LensChannel &channel : channels) {
    SCOPED_TRACE(channel.config().name + " (" + channel.encoder().name() + ")");
    const hal::lens::EncoderStatus status = channel.encoder().status();
    EXPECT_EQ(status.malformed + status.lost + status.missed_edges, 0u) << status.detail;
    ASSERT_TRUE(channel.last_reading().has_value());
    ASSERT_TRUE(channel.last_reading()->focus.has_value());
    // The quadrature axis homes at 8000 on the way down, to within a count.
    EXPECT_NEAR(*channel.last_reading()->focus, 2100, 1);
    const lens_control::LensState state = channel.state_at(now);
    EXPECT_TRUE(state.calibrated);
    EXPECT_NEAR(state.focus_distance_m.value, 0.400, 0.002);
    std::printf("%-6s last focus %d counts -> %.4f m, %llu readings\n",
                channel.config().name.c_str(), *channel.last_reading()->focus,
                state.focus_distance_m.value,
                (unsigned long long)channel.encoder().status().readings);
  }
}

// A small trace that jumps by 2^31 counts would have the simulated GPIO chip
// compute every edge of the jump ahead (gigabytes): refused, naming it.
TEST_F(LensSources, SimulatedGpioRefusesAnImpossibleJump) {
  {
    std::ofstream out(dir_ / "jump.csv");
    out << "# camhead lens trace v1\nt_s,focus,iris,zoom,focus_m,f_stop,focal_mm\n"
        << "0,-2147483648,,,,,\n0.01,2147483647,,,,,\n";
  }
  const Board board = parse_board(R"({
      "format": "camhead-board", "version": 1, "name": "jump",
      "lens": {"sources": [
        {"name": "gpio", "type": "gpio", "chip": "sim",
         "axes": {"focus": {"a": 0, "b": 1}}, "simulate": "jump.csv"}]}})",
                                  dir_ / "board.json");
  try {
    (void)open_lens_channels(board);
    FAIL() << "opened";
  } catch (const std::exception &e) {
    EXPECT_NE(std::string(e.what()).find("jump.csv"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("more than the simulated GPIO chip follows"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(LensSources, BoardWithoutProfileUsesTheFlaggedFallback) {
  write_trace();
  const Board board = parse_board(R"({"format": "camhead-board", "version": 1, "name": "t",
      "lens": {"sources": [{"type": "trace", "file": "pull.csv"}]}})",
                                  dir_ / "board.json");
  EXPECT_FALSE(load_board_profile(board).calibrated());
}

TEST_F(LensSources, AMissingTraceIsNamedWithItsSource) {
  const Board board = parse_board(R"({"format": "camhead-board", "version": 1, "name": "t",
      "lens": {"sources": [{"name": "pull", "type": "trace", "file": "nope.csv"}]}})",
                                  dir_ / "board.json");
  try {
    static_cast<void>(open_lens_channels(board));
    FAIL() << "no error";
  } catch (const std::exception &e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("lens source \"pull\""), std::string::npos) << message;
    EXPECT_NE(message.find("nope.csv"), std::string::npos) << message;
  }
}

TEST(LensSample, CarriesCountsAndCalibratedValues) {
  hal::lens::EncoderReading r;
  r.t_ns = 42;
  r.focus = 7;
  r.zoom = -3;
  r.focus_distance_m = 2.0;
  r.f_stop = 2.8;
  const lens_control::EncoderSample s = to_encoder_sample(r);
  EXPECT_EQ(s.t_ns, 42);
  EXPECT_EQ(s.focus, 7);
  EXPECT_FALSE(s.iris.has_value());
  EXPECT_EQ(s.zoom, -3);
  EXPECT_EQ(s.focus_distance_m, 2.0);
  EXPECT_EQ(s.f_number, 2.8);
  EXPECT_FALSE(s.focal_length_mm.has_value());
}

} // namespace
} // namespace camhead::pipeline
