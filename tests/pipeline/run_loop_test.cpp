// The live pipeline end to end (run_loop.h), as `camhead run` runs it: a
// camera frame that nothing virtual touches reaches the output byte for
// byte; a camera that goes away leaves the outputs running on the
// placeholder and is taken up again; drops are counted, never hidden.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "board.h"
#include "run/run_loop.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;

const fs::path kLenses = fs::path(CAMHEAD_SOURCE_DIR) / "scenes" / "lenses";

class RunLoop : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("camhead_run_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string &name, const std::string &text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }

  // A scene of real objects only, lit, at w x h.
  fs::path real_scene(int w, int h) const {
    return write("scene.json", R"({"render": {"width": )" + std::to_string(w) + R"(, "height": )" +
                                   std::to_string(h) + R"(, "samples": 2},
      "camera": {"position": [0, 0.7, 0], "look_at": [0, 0.3, -2], "up": [0, 1, 0],
                 "focal_length_mm": 35, "sensor_width_mm": 36,
                 "f_number": 2, "focus_distance_m": 2},
      "materials": {"grey": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
      "objects": [
        {"name": "floor", "type": "plane", "center": [0, 0, -3], "size": [10, 10], "material": "grey", "real": true},
        {"name": "crate", "type": "box", "center": [0.3, 0.2, -2], "size": [0.4, 0.4, 0.4], "material": "grey", "real": true}],
      "lights": [{"name": "key", "type": "point", "position": [-1, 2, -1], "power_W": 200}]})");
  }

  Board board(const std::string &camera, const fs::path &scene) const {
    return load_board(write("board.json", R"({"format": "camhead-board", "version": 1, "name": "t",
      "lens": {"profile": ")" + (kLenses / "example_35mm.json").string() +
                                              R"(",
               "sources": [{"type": "trace", "file": ")" +
                                              (kLenses / "sim_focus_pull.csv").string() +
                                              R"("}]},
      "camera": )" + camera + R"(, "scene": ")" +
                                              scene.string() + R"("})"));
  }

  fs::path dir_;
};

// Y4M 4:2:2 frames of w x h as the file camera reads them.
std::string y4m_422(int w, int h, const std::vector<std::vector<std::uint8_t>> &planar_frames) {
  std::string text = "YUV4MPEG2 W" + std::to_string(w) + " H" + std::to_string(h) +
                     " F25:1 Ip A1:1 C422 XCOLORRANGE=LIMITED\n";
  for (const auto &frame : planar_frames) {
    text += "FRAME\n";
    text.append(reinterpret_cast<const char *>(frame.data()), frame.size());
  }
  return text;
}

// The frames of a Y4M file, each as its planar bytes.
std::vector<std::string> y4m_frames(const fs::path &file, std::size_t frame_bytes) {
  std::ifstream in(file, std::ios::binary);
  std::string header;
  std::getline(in, header);
  std::vector<std::string> frames;
  std::string marker;
  while (std::getline(in, marker)) {
    EXPECT_EQ(marker.substr(0, 5), "FRAME");
    std::string bytes(frame_bytes, '\0');
    in.read(bytes.data(), std::streamsize(frame_bytes));
    if (in.gcount() != std::streamsize(frame_bytes))
      break;
    frames.push_back(bytes);
  }
  return frames;
}

std::vector<std::uint64_t> recorded_sequences(const fs::path &stats) {
  std::vector<std::uint64_t> sequences;
  std::ifstream in(stats);
  for (std::string line; std::getline(in, line);) {
    const std::size_t at = line.find("\"sequence\":");
    EXPECT_NE(at, std::string::npos) << line;
    sequences.push_back(std::stoull(line.substr(at + 11)));
    for (const char *field : {"\"capture_ns\":", "\"exposure_mid_ns\":", "\"output_ns\":",
                              "\"focus_m\":", "\"f_number\":", "\"focal_length_mm\":", "\"rpp\":",
                              "\"dropped_before\":", "\"trace_ms\":"})
      EXPECT_NE(line.find(field), std::string::npos) << field << " missing in " << line;
  }
  return sequences;
}

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

  const std::vector<std::uint64_t> sequences = recorded_sequences(dir_ / "stats.jsonl");
  const std::vector<std::string> out = y4m_frames(dir_ / "out.y4m", frames[0].size());
  ASSERT_EQ(out.size(), sequences.size());
  ASSERT_EQ(summary.frames_out, out.size());
  ASSERT_GE(out.size(), 1u);
  EXPECT_EQ(summary.frames_in, std::uint64_t(n));
  // Frames the renderer had no time for are counted, and only those are missing.
  EXPECT_EQ(summary.frames_out + summary.render_busy + summary.output_busy, std::uint64_t(n));
  for (std::size_t k = 0; k < out.size(); ++k) {
    ASSERT_LT(sequences[k], std::uint64_t(n));
    const auto &expect = frames[sequences[k]];
    EXPECT_TRUE(std::equal(expect.begin(), expect.end(),
                           reinterpret_cast<const std::uint8_t *>(out[k].data())))
        << "output frame " << k << " (camera frame " << sequences[k] << ") differs";
  }
}

TEST_F(RunLoop, LostCameraShowsThePlaceholderAndIsTakenUpAgain) {
  RunOptions options;
  options.board = board(R"({"type": "sim", "width": 32, "height": 16, "fps": 25,
                            "disconnect_after_frames": 5, "disconnect_s": 1.5})",
                        real_scene(32, 16));
  options.outputs = {"null"};
  options.duration_s = 3.5;
  options.status = nullptr;
  const RunSummary summary = run_pipeline(options);
  EXPECT_EQ(summary.camera_reconnects, 1u);
  EXPECT_GE(summary.placeholders, 2u) << "1.5 s without frames, a placeholder every 0.5 s";
  EXPECT_GT(summary.frames_out, 10u) << "frames after the camera came back";
}

TEST_F(RunLoop, RefusesABoardWithoutCameraOrOutput) {
  RunOptions options;
  options.board = load_board(resolve_board("sim"));
  options.board.camera.reset();
  EXPECT_THROW(run_pipeline(options), std::runtime_error);
  options.board = load_board(resolve_board("sim"));
  options.board.outputs.clear();
  try {
    run_pipeline(options);
    ADD_FAILURE() << "ran without an output";
  } catch (const std::runtime_error &e) {
    EXPECT_NE(std::string(e.what()).find("no output"), std::string::npos) << e.what();
  }
}

} // namespace
} // namespace camhead::pipeline
