// Pose traces: a camera path read with every field checked, played with its
// time 0 at CLOCK_MONOTONIC 0 in a loop, in a camera head's axes.
#include <cmath>
#include <filesystem>
#include <string>

#include <glm/geometric.hpp>

#include "tracking/pose_trace.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

constexpr std::int64_t kS = 1'000'000'000;

std::string error_of(const std::string &text) {
  try {
    static_cast<void>(parse_pose_trace(text, "/rigs/dolly.csv"));
  } catch (const PoseTraceError &e) {
    return e.what();
  }
  return "(no error)";
}

void expect_near(const glm::dvec3 &got, const glm::dvec3 &want, const char *what = "") {
  EXPECT_LT(glm::length(got - want), 1e-9)
      << what << ": (" << got.x << ", " << got.y << ", " << got.z << ") instead of (" << want.x
      << ", " << want.y << ", " << want.z << ")";
}

TEST(PoseTrace, ACameraHeadsAxesInTheWorld) {
  expect_near(pose_of_row(0, 0, 0, 0, 0, 0).forward(), {0, 0, -1});
  expect_near(pose_of_row(0, 0, 0, 90, 0, 0).forward(), {1, 0, 0}, "pan to the right");
  expect_near(pose_of_row(0, 0, 0, 0, 90, 0).forward(), {0, 1, 0}, "tilt up");
  expect_near(pose_of_row(0, 0, 0, 0, 0, 90).up(), {1, 0, 0}, "roll clockwise from behind");
  expect_near(pose_of_row(1, 2, 3, 0, 0, 0).position, {1, 2, 3}, "world metres");
}

TEST(PoseTrace, PlaysBetweenItsRowsInALoop) {
  const PoseTrace trace = parse_pose_trace("# camhead pose trace v1\n"
                                           "t_s,x_m,y_m,z_m,pan_deg,tilt_deg,roll_deg\n"
                                           "0,0,1,3,0,0,0\n"
                                           "1,1,1,3,20,0,0\n"
                                           "2,0,1,3,0,0,0\n",
                                           "dolly.csv");
  expect_near(trace.at(kS / 4).position, {0.25, 1, 3});
  expect_near(trace.at(kS / 2).forward(), pose_of_row(0, 0, 0, 10, 0, 0).forward(),
              "half way in time, half way round");
  expect_near(trace.at(2 * kS + kS / 4).position, {0.25, 1, 3}, "the loop");
  expect_near(trace.at(kS + kS / 2).position, {0.5, 1, 3}, "and back");
}

TEST(PoseTrace, AFileThatCannotBeReadIsNamed) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path();
  try {
    static_cast<void>(load_pose_trace(folder));
    ADD_FAILURE() << "a folder loaded";
  } catch (const PoseTraceError &e) {
    EXPECT_EQ(std::string(e.what()), folder.string() + ": (file): is a folder, not a file");
  }
}

TEST(PoseTrace, EveryMistakeIsNamed) {
  const std::string header = "# camhead pose trace v1\nt_s,x_m,y_m,z_m,pan_deg,tilt_deg,roll_deg\n";
  EXPECT_EQ(error_of("t_s,x_m\n0,0\n"),
            "/rigs/dolly.csv:1: format: the first line must be \"# camhead pose trace v1\"");
  EXPECT_EQ(error_of("# camhead pose trace v1\nt_s,x_m,y_m,z_m,pan_deg,tilt_deg\n0,0,0,0,0,0\n"),
            "/rigs/dolly.csv:2: roll_deg: missing from the header (a pose trace gives "
            "every row a whole pose)");
  EXPECT_EQ(error_of(header + "0,0,1,3,0,0,0\n1,0,1,3,0,0,0\n1,0,1,3,0,0,0\n"),
            "/rigs/dolly.csv:5: t_s: must be later than the row before (1.000000 s)");
  EXPECT_EQ(error_of(header + "0,0,1,3,0,95,0\n1,0,1,3,0,0,0\n"),
            "/rigs/dolly.csv:3: tilt_deg: must be within -90 .. 90");
  EXPECT_EQ(error_of(header + "0,0,1,3,0,0,nan\n1,0,1,3,0,0,0\n"),
            "/rigs/dolly.csv:3: roll_deg: must be a finite number");
  EXPECT_EQ(error_of(header + "0,0,1,3,0,0,0\n"),
            "/rigs/dolly.csv: (rows): a path needs at least two rows (a camera that stands "
            "still is a static pose)");
}

} // namespace
} // namespace camhead::pipeline
