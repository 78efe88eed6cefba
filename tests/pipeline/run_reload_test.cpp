// A running pipeline reloads its board (RunOptions::reload, a service's
// SIGHUP): the new scene and render settings are taken between two frames
// with no frame missed, and a reload that cannot be taken changes nothing.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "config/board.h"
#include "run/run_loop.h"
#include "run_test_support.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::vector<std::string> lines_of(const fs::path &file) {
  std::vector<std::string> lines;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
}

// Waits (bounded) until `file` says `text` `n` times.
bool wait_for_text(const fs::path &file, const std::string &text, std::size_t n) {
  for (int i = 0; i < 6000; ++i) {
    std::size_t seen = 0;
    for (const std::string &line : lines_of(file))
      seen += line.find(text) != std::string::npos ? 1 : 0;
    if (seen >= n)
      return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

// Waits (bounded) until the statistics file holds `n` composites, the last
// of them rendered with `setup`; false if it never does.
bool wait_for_composites(const fs::path &stats, std::size_t n, int setup) {
  const std::string mark = "\"setup\":" + std::to_string(setup) + ",";
  for (int i = 0; i < 6000; ++i) {
    std::size_t composites = 0;
    bool last_has_setup = false;
    for (const std::string &line : lines_of(stats))
      if (line.find("\"kind\":\"composite\"") != std::string::npos) {
        ++composites;
        last_has_setup = line.find(mark) != std::string::npos;
      }
    if (composites >= n && last_has_setup)
      return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

TEST_F(RunLoop, AReloadTakesTheNewSceneBetweenTwoFramesAndARefusedOneChangesNothing) {
  // Before: real objects only, 2 rays per pixel (nothing virtual is traced).
  const fs::path plain = real_scene(32, 16);
  // After: the same with a virtual ball in front of the crate.
  std::string text;
  {
    std::ifstream in(plain);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string crate = R"("real": true}],)";
  ASSERT_NE(text.rfind(crate), std::string::npos);
  text.replace(text.rfind(crate), crate.size(),
               R"("real": true}, {"name": "ball", "type": "sphere", "center": [-0.2, 0.3, -1.5], )"
               R"("radius": 0.25, "material": "grey"}],)");
  const fs::path with_ball = write("ball.json", text);
  const std::string camera = R"({"type": "sim", "width": 32, "height": 16, "fps": 25})";
  const auto render = [](int rpp) {
    return R"(, "render": {"executor": "cpu", "rays_per_pixel": )" + std::to_string(rpp) + "}";
  };
  RunOptions options;
  options.board = board(camera, plain, "", render(2));
  const fs::path board_file = options.board.file;
  std::atomic<bool> reload{false}, stop{false};
  options.reload = &reload;
  options.stop = &stop;
  options.outputs = {"null"};
  options.stats_file = dir_ / "stats.jsonl";
  options.duration_s = 120.0; // a guard: the operator below stops the run
  const fs::path said = dir_ / "status.txt";
  std::FILE *status = std::fopen(said.c_str(), "w");
  ASSERT_NE(status, nullptr);
  options.status = status;

  bool saw_reload = false, saw_refusals = false;
  std::thread operator_([&] {
    const fs::path stats = dir_ / "stats.jsonl";
    if (!wait_for_composites(stats, 5, 0)) {
      stop = true;
      return;
    }
    (void)board(camera, with_ball, "", render(5)); // rewrites board.json
    reload = true;
    saw_reload = wait_for_composites(stats, 10, 1);
    // A scene that does not load, then a board that changes the camera,
    // each after the last was refused.
    write("ball.json", "{\"render\": ");
    reload = true;
    saw_refusals = wait_for_text(said, "reload refused", 1);
    (void)board(R"({"type": "sim", "width": 64, "height": 16, "fps": 25})", plain, "", render(5));
    reload = true;
    saw_refusals = saw_refusals && wait_for_text(said, "reload refused", 2);
    // Frames go on with the reloaded setup.
    const std::size_t composites = lines_of(stats).size();
    saw_refusals = saw_refusals && wait_for_composites(stats, composites + 5, 1);
    stop = true;
  });
  const RunSummary summary = run_pipeline(options);
  operator_.join();
  ASSERT_TRUE(saw_reload) << "no frame of the reloaded setup within a minute";
  ASSERT_TRUE(saw_refusals) << "no refusals, or no frames after them, within a minute";

  EXPECT_EQ(summary.reloads, 1u);
  EXPECT_EQ(summary.reloads_refused, 2u);
  // Every composite before the reload rendered the plain scene at 2 rays,
  // every one after it the ball at 5: one switch, between two frames.
  const std::vector<std::string> lines = lines_of(dir_ / "stats.jsonl");
  int setup = 0;
  std::size_t switched_at = 0;
  bool composited = false;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string &line = lines[i];
    if (line.find("\"kind\":\"composite\"") == std::string::npos) {
      // Before the first composite a slow start shows the placeholder (a
      // sanitizer build's first frame takes seconds); after it, the camera
      // never went away.
      EXPECT_FALSE(composited && line.find("placeholder") != std::string::npos) << line;
      continue;
    }
    composited = true;
    const int s = int(json_number(line, "setup"));
    ASSERT_GE(s, setup) << line;
    ASSERT_LE(s, 1) << "a refused reload was taken: " << line;
    if (s != setup)
      switched_at = i;
    setup = s;
    EXPECT_EQ(json_number(line, "rpp"), s == 0 ? 2.0 : 5.0) << line;
    if (s == 0)
      EXPECT_EQ(json_number(line, "traced"), 0.0) << "nothing virtual: " << line;
    else
      EXPECT_GT(json_number(line, "traced"), 0.0) << "the ball: " << line;
  }
  ASSERT_GT(switched_at, 0u);
  // No gap: the frame before the switch was a composite of the old setup,
  // not a repeat filling in while the new one was made.
  EXPECT_NE(lines[switched_at - 1].find("\"setup\":0,"), std::string::npos)
      << lines[switched_at - 1];

  // What the operator reads: each outcome on a line of its own, naming the
  // file and field at fault.
  std::fclose(status);
  std::string text_said;
  for (const std::string &line : lines_of(said))
    text_said += line + "\n";
  EXPECT_NE(text_said.find("camhead run: reloaded " + board_file.string() + ": setup 1"),
            std::string::npos)
      << text_said;
  EXPECT_NE(
      text_said.find("reload refused, the run goes on as it was: " + (dir_ / "ball.json").string()),
      std::string::npos)
      << text_said;
  EXPECT_NE(text_said.find("reload refused, the run goes on as it was: " + board_file.string() +
                           ": camera.width: changed"),
            std::string::npos)
      << text_said;
}

} // namespace
} // namespace camhead::pipeline
