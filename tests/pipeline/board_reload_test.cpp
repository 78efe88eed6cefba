// A reload's board check (run/board_reload.h): what a frame is rendered
// with may change, what would take an output down or a device away is
// refused naming the field, and a board that does not load is refused with
// its own error.
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <unistd.h>

#include "config/board.h"
#include "run/board_reload.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = fs::path(CAMHEAD_SOURCE_DIR);

class BoardReload : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("camhead_reload_" + std::to_string(::getpid()) + "_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The board's text with `changes` in place of the defaults below.
  std::string text(const std::map<std::string, std::string> &changes = {}) const {
    std::map<std::string, std::string> v = {
        {"NAME", "\"rig\""},
        {"PROFILE", "\"" + (kSource / "scenes/lenses/example_35mm.json").string() + "\""},
        {"SOURCES", "[{\"name\": \"pull\", \"type\": \"trace\", \"file\": \"" +
                        (kSource / "scenes/lenses/sim_focus_pull.csv").string() + "\"}]"},
        {"CAMERA", R"({"type": "sim", "width": 32, "height": 16, "fps": 25})"},
        {"SCENE", "\"" + (kSource / "scenes/sim_rig.json").string() + "\""},
        {"POSE", R"({"position": [0, 1, 0], "look_at": [0, 1, -1]})"},
        {"OUTPUTS", R"(["null"])"},
        {"RENDER", R"({"executor": "cpu", "rays_per_pixel": 2})"}};
    for (const auto &[key, value] : changes)
      v[key] = value;
    return R"({"format": "camhead-board", "version": 1, "name": )" + v["NAME"] +
           R"(, "lens": {"profile": )" + v["PROFILE"] + R"(, "sources": )" + v["SOURCES"] +
           R"(}, "camera": )" + v["CAMERA"] + R"(, "scene": )" + v["SCENE"] + R"(, "pose": )" +
           v["POSE"] + R"(, "outputs": )" + v["OUTPUTS"] + R"(, "render": )" + v["RENDER"] + "}";
  }

  fs::path write(const std::string &board_text) const {
    std::ofstream(dir_ / "rig.json", std::ios::trunc) << board_text;
    return dir_ / "rig.json";
  }

  // What reread_board() says of the board file rewritten with `changes`:
  // "" when it takes it.
  std::string reload_error(const std::map<std::string, std::string> &changes) const {
    const Board running = load_board(write(text()));
    write(text(changes));
    try {
      (void)reread_board(running);
    } catch (const std::exception &e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

TEST_F(BoardReload, TakesTheSceneTheLensProfileTheRenderSettingsAndAStaticPose) {
  const Board running = load_board(write(text()));
  write(
      text({{"NAME", "\"rig, relit\""},
            {"PROFILE", "\"" + (kSource / "scenes/lenses/example_zoom_24_70.json").string() + "\""},
            {"SCENE", "\"" + (kSource / "scenes/ar_demo.json").string() + "\""},
            {"POSE", R"({"type": "static", "position": [0, 1.5, 0], "look_at": [0, 1, -2]})"},
            {"RENDER", R"({"executor": "cpu", "min_rays_per_pixel": 4, "adaptive": true})"}}));
  const Board next = reread_board(running);
  EXPECT_EQ(next.name, "rig, relit");
  EXPECT_EQ(next.lens.profile->filename(), "example_zoom_24_70.json");
  EXPECT_EQ(next.scene->filename(), "ar_demo.json");
  EXPECT_EQ(next.pose->position[1], 1.5);
  EXPECT_EQ(next.render.min_rays_per_pixel, 4u);
  EXPECT_FALSE(next.render.rays_per_pixel.has_value());
  EXPECT_TRUE(next.render.adaptive);
}

TEST_F(BoardReload, RefusesWhatTakesARestartNamingTheField) {
  const std::string file = (dir_ / "rig.json").string();
  EXPECT_EQ(reload_error({{"CAMERA", R"({"type": "sim", "width": 64, "height": 16, "fps": 25})"}})
                .rfind(file + ": camera.width: changed: ", 0),
            0u);
  EXPECT_EQ(reload_error({{"OUTPUTS", R"(["null", "file:/tmp/x.y4m"])"}})
                .rfind(file + ": outputs: changed", 0),
            0u);
  EXPECT_EQ(
      reload_error(
          {{"SOURCES", "[{\"name\": \"pull\", \"type\": \"trace\", \"file\": \"" +
                           (kSource / "scenes/lenses/webcam_fixed_focus.csv").string() + "\"}]"}})
          .rfind(file + ": lens.sources[0].file: changed", 0),
      0u);
  EXPECT_EQ(reload_error({{"RENDER", R"({"executor": "gpu", "rays_per_pixel": 2})"}})
                .rfind(file + ": render.executor: changed", 0),
            0u);
  // A static pose's numbers may change, its kind may not: a tracked pose
  // names a source that runs.
  EXPECT_EQ(reload_error({{"POSE", R"({"type": "trace", "file": ")" +
                                       (kSource / "scenes/paths/sim_dolly.csv").string() + "\"}"}})
                .rfind(file + ": pose: changed", 0),
            0u);
  // Nothing but the fixed part compared: whitespace and key order are not a change.
  EXPECT_EQ(
      reload_error({{"CAMERA", R"({"fps": 25,   "type": "sim", "width": 32, "height": 16})"}}), "");
}

TEST_F(BoardReload, ABoardThatDoesNotLoadIsRefusedWithItsOwnError) {
  const Board running = load_board(write(text()));
  write(text().substr(0, 40));
  EXPECT_THROW((void)reread_board(running), BoardError);
  write(text({{"RENDER", R"({"min_rays_per_pixel": 9, "max_rays_per_pixel": 4})"}}));
  try {
    (void)reread_board(running);
    ADD_FAILURE() << "taken";
  } catch (const BoardError &e) {
    EXPECT_NE(std::string(e.what()).find("render.min_rays_per_pixel"), std::string::npos)
        << e.what();
  }
}

} // namespace
} // namespace camhead::pipeline
