// Every path a run reads and writes, checked against the others before
// anything is opened for writing (run_paths.h): an output or the statistics
// file never lands on an input, by whatever name it is reached.
#include <filesystem>
#include <string>
#include <vector>

#include "run/run_paths.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;

// "(no clash)", or the error.
std::string clash(const std::vector<RunPath> &paths) {
  try {
    check_run_paths(paths);
  } catch (const RunPathError &e) {
    return e.what();
  }
  return "(no clash)";
}

RunPath input(const std::string &role, const fs::path &path, bool sequence = false) {
  return {role, path, false, sequence};
}

RunPath output(const std::string &role, const fs::path &path, bool sequence = false) {
  return {role, path, true, sequence};
}

TEST(RunPaths, AnOutputOnAnInputIsRefusedByWhateverNameItIsReached) {
  const test::ScratchDir dir;
  const fs::path take = dir.write("take.y4m", "YUV4MPEG2");
  fs::create_directory(dir.path() / "sub");
  fs::create_symlink(take, dir.path() / "alias.y4m");
  const RunPath camera = input("the camera's take", take);
  for (const fs::path &name :
       {take, dir.path() / "alias.y4m", dir.path() / "sub" / ".." / "take.y4m"})
    EXPECT_EQ(clash({camera, output("file:x", name)}),
              "file:x: writes to " + name.string() +
                  ", which is the camera's take that this run reads; writing there would "
                  "destroy it: write somewhere else")
        << name;
  EXPECT_EQ(clash({camera, output("file:other.y4m", dir.path() / "other.y4m"),
                   output("--record-stats", dir.path() / "stats.jsonl")}),
            "(no clash)");
}

TEST(RunPaths, TwoOutputsOnOneFileOrDeviceAreRefused) {
  const test::ScratchDir dir;
  // Neither exists yet: compared by the paths they will have.
  EXPECT_EQ(clash({output("file:a.y4m", dir.path() / "a.y4m"),
                   output("--record-stats", dir.path() / "." / "a.y4m")}),
            "--record-stats: writes to " + (dir.path() / "." / "a.y4m").string() +
                " as file:a.y4m does; give each output its own file or device");
  // A device reached by two names is one device; here /dev/null, which any
  // machine has, stands for a loopback webcam.
  EXPECT_NE(clash({input("the camera", "/dev/null"), output("v4l2:/dev/null", "/dev/null")}),
            "(no clash)");
}

// A PNG sequence's numbered names cannot be told from the inputs' own, so
// it needs a folder that holds none of them.
TEST(RunPaths, APngSequenceWritesIntoAFolderOfItsOwn) {
  const test::ScratchDir dir;
  fs::create_directory(dir.path() / "take");
  const RunPath camera = input("the camera's take", dir.path() / "take" / "%05d.png", true);
  EXPECT_EQ(clash({camera, output("file:take/%05d.png", dir.path() / "take" / "%05d.png", true)}),
            "file:take/%05d.png: writes its frames into " + (dir.path() / "take").string() +
                ", where the camera's take reads its own; give each sequence a folder of its "
                "own");
  // A file among the sequence's frames, whichever comes first.
  EXPECT_EQ(clash({camera, output("--record-stats", dir.path() / "take" / "00001.png")}),
            "--record-stats: writes " + (dir.path() / "take" / "00001.png").string() +
                " among the frames the camera's take reads (" + camera.path.string() +
                "); write somewhere else");
  EXPECT_EQ(clash({output("file:out/%d.png", dir.path() / "out" / "%d.png", true),
                   output("--record-stats", dir.path() / "out" / "7.png")}),
            "--record-stats: writes " + (dir.path() / "out" / "7.png").string() +
                " among the frames file:out/%d.png writes (" +
                (dir.path() / "out" / "%d.png").string() + "); write somewhere else");
  // Bare names are in the working folder.
  EXPECT_EQ(clash({output("file:%05d.png", "%05d.png", true), output("--record-stats", "1.png")}),
            "--record-stats: writes 1.png among the frames file:%05d.png writes (%05d.png); write "
            "somewhere else");
  // The camera's folder itself, and a plate among the outputs' frames.
  EXPECT_NE(clash({input("the camera's take", dir.path() / "take", true),
                   output("file:take/f%d.png", dir.path() / "take" / "f%d.png", true)}),
            "(no clash)");
  EXPECT_EQ(clash({input("the scene's plate", dir.path() / "out" / "plate.PNG"),
                   output("file:out/%d.png", dir.path() / "out" / "%d.png", true)}),
            "file:out/%d.png: writes its frames into " + (dir.path() / "out").string() +
                ", which holds the scene's plate (" + (dir.path() / "out" / "plate.PNG").string() +
                ") that this run reads; give the sequence a folder of its own");
  // A folder of its own; a Y4M beside the sequence is no frame of it.
  EXPECT_EQ(clash({camera, output("file:out/%05d.png", dir.path() / "out" / "%05d.png", true),
                   input("the board", dir.path() / "out" / "board.json"),
                   output("file:out/take.y4m", dir.path() / "out" / "take.y4m")}),
            "(no clash)");
  EXPECT_NE(clash({output("file:out/a%d.png", dir.path() / "out" / "a%d.png", true),
                   output("file:out/b%d.png", dir.path() / "out" / "b%d.png", true)}),
            "(no clash)");
}

} // namespace
} // namespace camhead::pipeline
