// The trackers' axes in camhead's world: which way a camera looks and which
// way the top of its picture points for each protocol's pan, tilt and roll,
// and OpenTrackIO's angles back from a world pose.
#include <cmath>
#include <random>

#include <glm/geometric.hpp>

#include "tracking/tracker_axes.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

using hal::lens::TrackedPose;

void expect_near(const glm::dvec3 &got, const glm::dvec3 &want, const char *what) {
  EXPECT_LT(glm::length(got - want), 1e-12)
      << what << ": (" << got.x << ", " << got.y << ", " << got.z << "), expected (" << want.x
      << ", " << want.y << ", " << want.z << ")";
}

const glm::dvec3 kRight(1, 0, 0), kUp(0, 1, 0), kAhead(0, 0, -1); // camhead's world

TEST(TrackerAxes, AtRestBothLookAlongTheStagesYWithZUp) {
  for (const CameraPose &pose : {from_freed({}), from_opentrackio({})}) {
    expect_near(pose.forward(), kAhead, "forward");
    expect_near(pose.up(), kUp, "up");
  }
}

TEST(TrackerAxes, StageXYZIsWorldXMinusZY) {
  // X right, Y forward (away from the camera at rest), Z up.
  const TrackedPose p{.x_m = 1.5, .y_m = 4.0, .z_m = 1.25};
  expect_near(from_freed(p).position, {1.5, 1.25, -4.0}, "freed");
  expect_near(from_opentrackio(p).position, {1.5, 1.25, -4.0}, "opentrackio");
}

TEST(TrackerAxes, FreedPansRightOpenTrackIoPansLeft) {
  expect_near(from_freed({.pan_deg = 90}).forward(), kRight, "freed pan +90");
  expect_near(from_opentrackio({.pan_deg = 90}).forward(), -kRight, "opentrackio pan +90");
  expect_near(from_freed({.pan_deg = 90}).up(), kUp, "a pan keeps the picture upright");
}

TEST(TrackerAxes, TiltUpAndRollClockwiseAlike) {
  for (auto convert : {from_freed, from_opentrackio}) {
    expect_near(convert({.tilt_deg = 90}).forward(), kUp, "tilt +90 looks up");
    expect_near(convert({.tilt_deg = 90}).up(), -kAhead, "then the picture's top points back");
    // Clockwise seen from behind: the top of the picture leans right.
    expect_near(convert({.roll_deg = 90}).up(), kRight, "roll +90");
    expect_near(convert({.roll_deg = 90}).forward(), kAhead, "a roll keeps the view");
  }
}

TEST(TrackerAxes, PanThenTiltThenRoll) {
  // Panned right 90 and tilted up 45: the view rises to the right, and a
  // roll turns about that view, not about the stage's axes.
  const CameraPose p = from_freed({.pan_deg = 90, .tilt_deg = 45, .roll_deg = 30});
  const double h = std::sqrt(0.5);
  expect_near(p.forward(), {h, h, 0}, "forward");
  // Unrolled, the top points up and back along the view: (-h, h, 0); the
  // roll turns it 30 degrees towards the camera's right, world +z.
  expect_near(p.up(),
              std::cos(std::numbers::pi / 6) * glm::dvec3(-h, h, 0) +
                  std::sin(std::numbers::pi / 6) * glm::dvec3(0, 0, 1),
              "up");
}

TEST(TrackerAxes, OpenTrackIoAnglesComeBack) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> angle(-179.0, 179.0), tilt(-89.0, 89.0), at(-50, 50);
  for (int i = 0; i < 1000; ++i) {
    const TrackedPose p{.x_m = at(random),
                        .y_m = at(random),
                        .z_m = at(random),
                        .pan_deg = angle(random),
                        .tilt_deg = tilt(random),
                        .roll_deg = angle(random)};
    const TrackedPose back = to_opentrackio(from_opentrackio(p));
    EXPECT_NEAR(back.x_m, p.x_m, 1e-12);
    EXPECT_NEAR(back.y_m, p.y_m, 1e-12);
    EXPECT_NEAR(back.z_m, p.z_m, 1e-12);
    EXPECT_NEAR(back.pan_deg, p.pan_deg, 1e-9);
    EXPECT_NEAR(back.tilt_deg, p.tilt_deg, 1e-9);
    EXPECT_NEAR(back.roll_deg, p.roll_deg, 1e-9);
  }
}

TEST(TrackerAxes, AFreedPoseSentOnAsOpenTrackIoPansTheOtherWay) {
  const TrackedPose back = to_opentrackio(
      from_freed({.x_m = 1, .y_m = -2, .z_m = 1.5, .pan_deg = 30, .tilt_deg = 10, .roll_deg = 5}));
  EXPECT_NEAR(back.x_m, 1.0, 1e-12);
  EXPECT_NEAR(back.y_m, -2.0, 1e-12);
  EXPECT_NEAR(back.z_m, 1.5, 1e-12);
  EXPECT_NEAR(back.pan_deg, -30.0, 1e-9);
  EXPECT_NEAR(back.tilt_deg, 10.0, 1e-9);
  EXPECT_NEAR(back.roll_deg, 5.0, 1e-9);
}

TEST(TrackerAxes, StraightUpOrDownKeepsTheView) {
  for (const double tilt : {90.0, -90.0})
    for (const double pan : {-120.0, 0.0, 35.0}) {
      const CameraPose p = from_opentrackio({.pan_deg = pan, .tilt_deg = tilt});
      const CameraPose back = from_opentrackio(to_opentrackio(p));
      expect_near(back.forward(), p.forward(), "forward");
      expect_near(back.up(), p.up(), "up");
    }
}

} // namespace
} // namespace camhead::pipeline
