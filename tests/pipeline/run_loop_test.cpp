// The live pipeline end to end (run_loop.h), as `camhead run` runs it: a
// camera frame that nothing virtual touches reaches the output byte for
// byte; a camera that goes away leaves the outputs running on the
// placeholder and is taken up again; drops are counted, never hidden.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "camhead/hal/lens/trace/lens_trace.h"
#include "camhead/lens_control/lens_profile.h"
#include "config/board.h"
#include "run/run_loop.h"
#include "run_test_support.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;

TEST_F(RunLoop, CameraFramesThatNothingVirtualTouchesLeaveByteForByte) {
  const int w = 48, h = 32, n = 6;
  std::mt19937 rng(5);
  std::vector<std::vector<std::uint8_t>> frames(n,
                                                std::vector<std::uint8_t>(std::size_t(w) * h * 2));
  for (auto &frame : frames)
    for (std::uint8_t &b : frame)
      b = std::uint8_t(16 + rng() % 220);
  const fs::path input = write("in.y4m", y4m_422(w, h, frames));
  RunOptions options;
  options.board = board(R"({"type": "file", "path": ")" + input.string() +
                            R"(", "loop": false, "realtime": false, "width": 48, "height": 32})",
                        real_scene(w, h));
  options.outputs = {"file:" + (dir_ / "out.y4m").string()};
  options.stats_file = dir_ / "stats.jsonl";
  options.status = nullptr;
  const RunSummary summary = run_pipeline(options);

  const std::vector<CompositeRecord> records = recorded_composites(dir_ / "stats.jsonl");
  const std::vector<std::string> out = y4m_frames(dir_ / "out.y4m", frames[0].size());
  ASSERT_EQ(summary.frames_out, records.size());
  ASSERT_EQ(out.size(), records.size() + summary.repeats + summary.placeholders);
  ASSERT_GE(records.size(), 1u);
  EXPECT_EQ(summary.frames_in, std::uint64_t(n));
  // A file not played in real time waits for the renderer: nothing dropped.
  EXPECT_EQ(summary.frames_out, std::uint64_t(n));
  EXPECT_EQ(summary.render_busy + summary.output_busy, 0u);
  for (const CompositeRecord &r : records) {
    ASSERT_LT(r.sequence, std::uint64_t(n));
    ASSERT_LT(r.output_frame, out.size());
    const auto &expect = frames[r.sequence];
    EXPECT_TRUE(std::equal(expect.begin(), expect.end(),
                           reinterpret_cast<const std::uint8_t *>(out[r.output_frame].data())))
        << "output frame " << r.output_frame << " (camera frame " << r.sequence << ") differs";
  }
}

// A take composited offline (a file camera not in real time) gets its
// composites and nothing else, however long each takes: a live output shows
// the last frame again after a while without a new one (here 1 ms, which
// every render outlasts), a file must not.
TEST_F(RunLoop, AnOfflineTakeGetsItsCompositesAlone) {
  // Three frames: while the first renders, the third waits to be taken, so
  // the run is not yet stopping.
  const int w = 48, h = 32, n = 3;
  const std::vector<std::vector<std::uint8_t>> frames(
      n, std::vector<std::uint8_t>(std::size_t(w) * h * 2, 128));
  const fs::path input = write("in.y4m", y4m_422(w, h, frames));
  // A lit virtual wall that fills the frame: every pixel traced.
  const fs::path scene = write("wall.json", R"({"render": {"width": 48, "height": 32, "samples": 1},
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0],
               "focal_length_mm": 35, "sensor_width_mm": 36, "f_number": 2, "focus_distance_m": 2},
    "materials": {"grey": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "objects": [{"name": "wall", "type": "plane", "center": [0, 0, -3], "size": [20, 20],
                 "rotation_deg": [90, 0, 0], "material": "grey", "real": false}],
    "lights": [{"name": "key", "type": "point", "position": [0, 1, -1], "power_W": 100}]})");
  RunOptions options;
  options.board = board(R"({"type": "file", "path": ")" + input.string() +
                            R"(", "loop": false, "realtime": false, "width": 48, "height": 32})",
                        scene, "", R"(, "render": {"executor": "cpu", "rays_per_pixel": 16})");
  options.repeat_after_s = 0.001;
  options.outputs = {"file:" + (dir_ / "out.y4m").string()};
  options.stats_file = dir_ / "stats.jsonl";
  options.status = nullptr;
  const RunSummary summary = run_pipeline(options);
  EXPECT_EQ(recorded_composites(dir_ / "stats.jsonl").size(), std::size_t(n));
  EXPECT_EQ(summary.frames_out, std::uint64_t(n));
  EXPECT_EQ(summary.repeats, 0u);
  EXPECT_EQ(summary.placeholders, 0u);
  EXPECT_EQ(y4m_frames(dir_ / "out.y4m", frames[0].size()).size(), std::size_t(n));
}

TEST_F(RunLoop, LostCameraShowsThePlaceholderAndIsTakenUpAgain) {
  RunOptions options;
  options.board = board(R"({"type": "sim", "width": 32, "height": 16, "fps": 25,
                            "disconnect_after_frames": 5, "disconnect_s": 1.5})",
                        real_scene(32, 16));
  options.outputs = {"null"};
  // The run ends on frames, not on the clock: on a loaded machine (the
  // sanitizer suite beside another test) the first composites can take
  // seconds, and a run of fixed length then ends before the camera is back.
  options.frames = 12;
  options.duration_s = 60.0; // only a guard against a camera never taken up
  options.status = nullptr;
  const RunSummary summary = run_pipeline(options);
  EXPECT_EQ(summary.camera_reconnects, 1u);
  EXPECT_GE(summary.placeholders, 2u) << "1.5 s without frames, a placeholder every 0.5 s";
  EXPECT_EQ(summary.frames_out, 12u) << "at least 7 frames after the camera came back";
}

// A camera that only stops sending (a capture card without signal) says
// nothing; after a second without frames the outputs show the placeholder
// all the same, not its last frame for as long as it stays silent.
TEST_F(RunLoop, SilentCameraShowsThePlaceholderToo) {
  RunOptions options;
  options.board = board(R"({"type": "sim", "width": 32, "height": 16, "fps": 25,
                            "disconnect_after_frames": 5, "disconnect_s": 3,
                            "disconnect_silently": true})",
                        real_scene(32, 16));
  options.outputs = {"null"};
  options.frames = 12; // on frames, not the clock: see the test above
  options.duration_s = 60.0;
  options.status = nullptr;
  const RunSummary summary = run_pipeline(options);
  EXPECT_EQ(summary.camera_reconnects, 0u) << "it never said it was gone";
  EXPECT_GE(summary.repeats, 1u) << "the last frame again within the first second";
  EXPECT_GE(summary.placeholders, 3u) << "3 s without frames: from 1 s on, one every 0.5 s";
  EXPECT_EQ(summary.frames_out, 12u) << "at least 7 frames after the camera came back";
}

TEST_F(RunLoop, LostLensSourceHoldsTheLastStateFlaggedStale) {
  // The focus pull played once at 100x: over in 60 ms, then the source is
  // gone (a finished trace reports itself disconnected).
  RunOptions options;
  options.board = board(R"({"type": "sim", "width": 32, "height": 16, "fps": 25})",
                        real_scene(32, 16), R"(, "loop": false, "speed": 100)");
  options.outputs = {"null"};
  options.stats_file = dir_ / "stats.jsonl";
  // On frames, not the clock: under the sanitizers and a loaded machine,
  // 1.5 s once gave fewer than the 10 frames this test reads.
  options.frames = 12;
  options.duration_s = 60.0;
  options.status = nullptr;
  (void)run_pipeline(options);
  const hal::lens::LensTrace trace = hal::lens::read_lens_trace(kLenses / "sim_focus_pull.csv");
  const auto profile = lens_control::LensProfile::load(kLenses / "example_35mm.json");
  const double last_focus = profile.focus_distance_m(*trace.readings.back().focus).value;
  std::size_t late = 0;
  for (const CompositeRecord &r : recorded_composites(dir_ / "stats.jsonl")) {
    if (r.output_frame < 5)
      continue; // the trace may still have been playing
    ++late;
    EXPECT_FALSE(r.lens_fresh) << "output frame " << r.output_frame;
    // In diopters, the unit blur goes with: near infinity a few counts of
    // encoder noise, extrapolated for the chain's 20 ms, move metres.
    EXPECT_NEAR(1.0 / r.focus_m, 1.0 / last_focus, 0.005) << "output frame " << r.output_frame;
  }
  EXPECT_GE(late, 5u);
}

// A camera hands a frame over once its exposure is done, and the frame is
// rendered with the lens of its mid-exposure, which the lens chain has
// readings around: every composite's lens state is fresh, the first
// included (it waits for the lens thread's first readings if it must),
// whether the take plays in real time or offline.
TEST_F(RunLoop, EveryFrameGetsTheLensStateOfItsMidExposure) {
  const int w = 48, h = 32, n = 8;
  const std::vector<std::vector<std::uint8_t>> frames(
      n, std::vector<std::uint8_t>(std::size_t(w) * h * 2, 128));
  const fs::path input = write("in.y4m", y4m_422(w, h, frames));
  for (const bool realtime : {true, false}) {
    RunOptions options;
    options.board = board(R"({"type": "file", "path": ")" + input.string() +
                              R"(", "loop": false, "realtime": )" + (realtime ? "true" : "false") +
                              R"(, "width": 48, "height": 32})",
                          real_scene(w, h));
    options.outputs = {"null"};
    options.stats_file = dir_ / "stats.jsonl";
    options.status = nullptr;
    const RunSummary summary = run_pipeline(options);
    const std::vector<CompositeRecord> records = recorded_composites(dir_ / "stats.jsonl");
    ASSERT_EQ(records.size(), std::size_t(n)) << (realtime ? "real time" : "offline");
    for (const CompositeRecord &r : records) {
      EXPECT_TRUE(r.lens_fresh) << (realtime ? "real time" : "offline") << ", frame " << r.sequence;
      // No camera hands a frame over before the middle of its exposure.
      if (realtime) {
        EXPECT_LT(r.exposure_mid_ns, r.delivered_ns) << "frame " << r.sequence;
      }
    }
    EXPECT_EQ(summary.lens_late, 0u);
  }
}

// A lens source that sends calibrated values only (a trace's focus_m,
// f_stop and focal_mm columns, as an engine's OpenTrackIO focusDistance and
// fStop come) drives the render: every frame has the trace's lens, fresh.
// (They were dropped on the way into the lens chain, and every frame had
// the profile's rest state, stale.)
TEST_F(RunLoop, ACalibratedTraceDrivesTheLens) {
  const int w = 48, h = 32, n = 6;
  const std::vector<std::vector<std::uint8_t>> frames(
      n, std::vector<std::uint8_t>(std::size_t(w) * h * 2, 128));
  const fs::path input = write("in.y4m", y4m_422(w, h, frames));
  std::string trace = "# camhead lens trace v1\nt_s,focus_m,f_stop,focal_mm\n";
  for (int k = 0; k <= 2000; ++k) // 20 s at 100 Hz
    trace += std::to_string(0.01 * k) + ",1.5,2.8,50\n";
  const fs::path trace_file = write("calibrated.csv", trace);
  for (const bool with_profile : {true, false}) {
    const std::string profile =
        with_profile ? R"("profile": ")" + (kLenses / "example_35mm.json").string() + "\", " : "";
    RunOptions options;
    options.board = load_board(write("board.json", R"({"format": "camhead-board", "version": 1,
      "name": "t", "lens": {)" + profile + R"("sources": [{"type": "trace", "file": ")" +
                                                       trace_file.string() + R"("}]},
      "camera": {"type": "file", "path": ")" + input.string() +
                                                       R"(", "loop": false, "realtime": false,
                 "width": 48, "height": 32},
      "scene": ")" + real_scene(w, h).string() + "\"}"));
    options.outputs = {"null"};
    options.stats_file = dir_ / "stats.jsonl";
    options.status = nullptr;
    const RunSummary summary = run_pipeline(options);
    EXPECT_EQ(summary.lens_late, 0u);
    std::ifstream stats(dir_ / "stats.jsonl");
    int composites = 0;
    for (std::string line; std::getline(stats, line);) {
      if (line.find("\"kind\":\"composite\"") == std::string::npos)
        continue;
      ++composites;
      EXPECT_NEAR(json_number(line, "focus_m"), 1.5, 1e-6) << line;
      EXPECT_NEAR(json_number(line, "f_number"), 2.8, 1e-6) << line;
      EXPECT_NEAR(json_number(line, "focal_length_mm"), 50.0, 1e-6) << line;
      EXPECT_NE(line.find("\"lens_fresh\":true"), std::string::npos) << line;
    }
    EXPECT_EQ(composites, n) << (with_profile ? "with a profile" : "without");
  }
}

// The frame budget's rays a pixel are a mean in sixteenths of a ray
// (frame_budget.h): between two whole numbers the frame gets the fraction
// too, spends it, and the record says so. An offline take at 5 fps leaves
// the budget room to grow from one ray to the board's most through
// fractions (1, 2, 3, 4.4375, 6.625, 8 here) on any machine that renders
// these 48x32 pixels in well under 200 ms; the lens moves every frame (a
// tolerance of 0), so each frame is a history's first, which gives its rays
// after the first where the picture lacks them, nothing moved into it (a
// history of moved samples traces whole rays:
// FrameRequest::extra_rays_per_pixel).
TEST_F(RunLoop, TheBudgetsFractionOfARayIsTracedAndRecorded) {
  const int w = 48, h = 32, n = 8;
  const std::vector<std::vector<std::uint8_t>> frames(
      n, std::vector<std::uint8_t>(std::size_t(w) * h * 2, 128));
  std::string take = y4m_422(w, h, frames);
  take.replace(take.find(" F25:1 "), 7, " F5:1 ");
  const fs::path input = write("in.y4m", take);
  std::string trace = "# camhead lens trace v1\nt_s,focus_m,f_stop,focal_mm\n";
  for (int k = 0; k <= 2000; ++k) // 20 s at 100 Hz, the focus 0.5 m further each second
    trace += std::to_string(0.01 * k) + "," + std::to_string(1.0 + 0.005 * k) + ",2.8,50\n";
  const fs::path trace_file = write("pull.csv", trace);
  // A lit virtual wall that fills the frame: every pixel traced.
  const fs::path scene = write("wall.json", R"({"render": {"width": 48, "height": 32, "samples": 1},
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0],
               "focal_length_mm": 50, "sensor_width_mm": 36, "f_number": 2.8, "focus_distance_m": 2},
    "materials": {"grey": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "objects": [{"name": "wall", "type": "plane", "center": [0, 0, -3], "size": [20, 20],
                 "rotation_deg": [90, 0, 0], "material": "grey", "real": false}],
    "lights": [{"name": "key", "type": "point", "position": [0, 1, -1], "power_W": 100}]})");
  RunOptions options;
  options.board = load_board(write("board.json", R"({"format": "camhead-board", "version": 1,
    "name": "t", "lens": {"sources": [{"type": "trace", "file": ")" +
                                                     trace_file.string() + R"("}]},
    "camera": {"type": "file", "path": ")" + input.string() +
                                                     R"(", "loop": false,
               "realtime": false, "width": 48, "height": 32},
    "scene": ")" + scene.string() + R"(",
    "render": {"executor": "cpu", "max_rays_per_pixel": 8, "accumulate_tolerance_px": 0,
               "reproject": false}})"));
  options.outputs = {"null"};
  options.stats_file = dir_ / "stats.jsonl";
  options.status = nullptr;
  (void)run_pipeline(options);
  std::ifstream stats(dir_ / "stats.jsonl");
  int composites = 0, with_a_fraction = 0;
  for (std::string line; std::getline(stats, line);) {
    if (line.find("\"kind\":\"composite\"") == std::string::npos)
      continue;
    ++composites;
    const double rpp = json_number(line, "rpp");
    EXPECT_EQ(rpp * 16.0, std::floor(rpp * 16.0)) << "not in sixteenths of a ray: " << line;
    if (rpp != std::floor(rpp))
      ++with_a_fraction;
    ASSERT_EQ(json_number(line, "traced"), 1.0) << line;
    // Shares are rounded at random, pixel by pixel: on average the budget,
    // within 0.013 rays (the rounding's standard deviation over 1536
    // pixels); the bound is 5 of those, or 2 %.
    const double traced_rpp = json_number(line, "camera_rays") / double(w * h);
    EXPECT_NEAR(traced_rpp, rpp, std::max(0.02 * rpp, 0.065)) << line;
  }
  EXPECT_EQ(composites, n);
  EXPECT_GE(with_a_fraction, 1) << "the budget grew through whole rays alone";
}

TEST_F(RunLoop, RefusesABoardWithoutCameraOrOutput) {
  RunOptions options;
  options.board = load_board(resolve_board("sim"));
  options.board.camera.reset();
  EXPECT_THROW(run_pipeline(options), std::runtime_error);
  options.board = load_board(resolve_board("sim"));
  options.board.outputs.clear();
  // Refused before the camera opens: the simulated one would first render
  // its world's loop (seconds) and say so.
  testing::internal::CaptureStderr();
  try {
    run_pipeline(options);
    ADD_FAILURE() << "ran without an output";
  } catch (const std::runtime_error &e) {
    EXPECT_NE(std::string(e.what()).find("no output"), std::string::npos) << e.what();
  }
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_EQ(said.find("simulated camera"), std::string::npos) << said;
}

} // namespace
} // namespace camhead::pipeline
