// The still filter of a tracked pose: a camera at rest is held (the mean of
// its first measurements, then unchanged), a camera that moves is taken as
// measured, and "moves" is what the picture of the target shows.
#include <array>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "tracking/still_pose.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

// A board 2 m ahead of a camera at rest.
const std::array<glm::dvec3, 4> kBoard = {glm::dvec3(-0.4, -0.3, -2.0), glm::dvec3(0.4, -0.3, -2.0),
                                          glm::dvec3(0.4, 0.3, -2.0), glm::dvec3(-0.4, 0.3, -2.0)};
constexpr double kFocalPx = 700.0;

CameraPose at(double x_mm, double pan_deg = 0.0) {
  return {{x_mm / 1000.0, 0.0, 0.0},
          glm::angleAxis(pan_deg * std::numbers::pi / 180.0, glm::dvec3(0.0, 1.0, 0.0))};
}

TEST(StillPose, WhatMovesIsThePicture) {
  // 1 mm across at 2 m: 0.35 px.
  EXPECT_NEAR(StillPoseFilter::moved_px(at(0.0), at(1.0), kFocalPx, kBoard), 0.35, 0.01);
  // A shift and the turn that keeps the board's middle where it was: its
  // corners move a twentieth as much (a planar target's weakest direction;
  // what is left is the second order of the corners' 14 degrees off the
  // axis).
  const double turn = std::atan(0.001 / 2.0) * 180.0 / std::numbers::pi;
  EXPECT_NEAR(StillPoseFilter::moved_px(at(0.0), at(1.0, turn), kFocalPx, kBoard), 0.0175, 0.001);
}

TEST(StillPose, AStillCameraIsHeldAtTheMeanOfItsFirstMeasurements) {
  StillPoseFilter filter; // gate 0.25 px, settle 8
  const double jitter_mm[] = {0.1, -0.1, 0.2, -0.2, 0.05, -0.05, 0.15, -0.15, 0.3, -0.3, 0.1};
  CameraPose held;
  for (std::size_t i = 0; i < std::size(jitter_mm); ++i) {
    held = filter.filter(at(jitter_mm[i]), kFocalPx, kBoard);
    if (i == 7) {
      EXPECT_NEAR(held.position.x, 0.0, 1e-12) << "the first eight's mean";
    }
  }
  EXPECT_NEAR(held.position.x, 0.0, 1e-12) << "then held, whatever the next say";
}

TEST(StillPose, AMovingCameraIsTakenAsMeasured) {
  StillPoseFilter filter;
  (void)filter.filter(at(0.0), kFocalPx, kBoard);
  const CameraPose moved = filter.filter(at(2.0), kFocalPx, kBoard); // 0.7 px: beyond the gate
  EXPECT_EQ(moved.position.x, 0.002);
  const CameraPose next = filter.filter(at(2.1), kFocalPx, kBoard); // at rest there
  EXPECT_NEAR(next.position.x, 0.00205, 1e-12) << "the mean of the two since it came to rest";
}

} // namespace
} // namespace camhead::pipeline
