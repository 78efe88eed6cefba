// A tracker's poses in time: interpolated between samples, extrapolated a
// little, held and flagged beyond, and moved back by the source's delay.
#include <cmath>
#include <numbers>
#include <optional>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "counting_new.h"
#include "tracking/pose_timeline.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

constexpr std::int64_t kMs = 1'000'000;

// At x metres, panned `degrees` to the left about the vertical.
CameraPose at(double x, double degrees) {
  return {{x, 1.5, 0.0},
          glm::angleAxis(degrees * std::numbers::pi / 180.0, glm::dvec3(0.0, 1.0, 0.0))};
}

// How far the pose has turned to the left, degrees.
double pan_of(const CameraPose &p) {
  const glm::dvec3 f = p.forward();
  return std::atan2(-f.x, -f.z) * 180.0 / std::numbers::pi;
}

TEST(PoseTimeline, EmptyUntilTheFirstPose) {
  const PoseTimeline timeline;
  EXPECT_FALSE(timeline.at(0));
}

TEST(PoseTimeline, BetweenTwoPosesMovesAndTurnsInProportion) {
  PoseTimeline timeline;
  ASSERT_TRUE(timeline.push(100 * kMs, at(0.0, 0.0)));
  ASSERT_TRUE(timeline.push(120 * kMs, at(1.0, 40.0)));
  const auto quarter = timeline.at(105 * kMs);
  ASSERT_TRUE(quarter);
  EXPECT_TRUE(quarter->fresh);
  EXPECT_NEAR(quarter->pose.position.x, 0.25, 1e-12);
  EXPECT_NEAR(pan_of(quarter->pose), 10.0, 1e-9) << "the turn, not the matrix, in proportion";
  EXPECT_NEAR(glm::length(quarter->pose.orientation), 1.0, 1e-12);
}

TEST(PoseTimeline, TurnsTheShortWayAcross180Degrees) {
  PoseTimeline timeline;
  ASSERT_TRUE(timeline.push(0, at(0.0, 170.0)));
  ASSERT_TRUE(timeline.push(20 * kMs, at(0.0, -170.0)));
  EXPECT_NEAR(std::abs(pan_of(timeline.at(10 * kMs)->pose)), 180.0, 1e-9);
}

TEST(PoseTimeline, ExtrapolatesAlongTheLastTwoAsFarAsItsBoundThenHolds) {
  PoseTimeline timeline; // 20 ms of extrapolation
  ASSERT_TRUE(timeline.push(0, at(0.0, 0.0)));
  ASSERT_TRUE(timeline.push(10 * kMs, at(0.1, 1.0)));
  const auto ahead = timeline.at(30 * kMs);
  ASSERT_TRUE(ahead);
  EXPECT_TRUE(ahead->fresh);
  EXPECT_NEAR(ahead->pose.position.x, 0.3, 1e-12);
  EXPECT_NEAR(pan_of(ahead->pose), 3.0, 1e-9);
  const auto late = timeline.at(200 * kMs);
  EXPECT_FALSE(late->fresh) << "a tracker silent for 190 ms";
  EXPECT_NEAR(late->pose.position.x, 0.3, 1e-12) << "held where the bound stopped it";
}

TEST(PoseTimeline, AcrossADropoutIsNotFresh) {
  PoseTimeline timeline; // stale after 50 ms between poses
  ASSERT_TRUE(timeline.push(0, at(0.0, 0.0)));
  ASSERT_TRUE(timeline.push(200 * kMs, at(2.0, 0.0)));
  const auto middle = timeline.at(100 * kMs);
  EXPECT_FALSE(middle->fresh);
  EXPECT_NEAR(middle->pose.position.x, 1.0, 1e-12);
  EXPECT_FALSE(timeline.at(-kMs)->fresh) << "older than the history";
}

TEST(PoseTimeline, TheDelayMovesPosesBackToTheirInstant) {
  PoseTimeline timeline(PoseTimelineParams{.delay_ns = 30 * kMs});
  ASSERT_TRUE(timeline.push(130 * kMs, at(0.0, 0.0))); // describes t = 100 ms
  ASSERT_TRUE(timeline.push(140 * kMs, at(1.0, 0.0))); // t = 110 ms
  EXPECT_NEAR(timeline.at(105 * kMs)->pose.position.x, 0.5, 1e-12);
  EXPECT_EQ(timeline.newest_ns(), 110 * kMs);
  // Before the first pose's instant: the first, held back, and said so.
  EXPECT_FALSE(timeline.at(100 * kMs)->before_first);
  const std::optional<PoseAt> earlier = timeline.at(99 * kMs);
  ASSERT_TRUE(earlier);
  EXPECT_TRUE(earlier->before_first);
  EXPECT_FALSE(earlier->fresh);
  EXPECT_EQ(earlier->pose.position.x, 0.0);
}

TEST(PoseTimeline, RefusesAPoseNotLaterThanTheNewest) {
  PoseTimeline timeline;
  ASSERT_TRUE(timeline.push(10 * kMs, at(1.0, 0.0)));
  EXPECT_FALSE(timeline.push(10 * kMs, at(2.0, 0.0)));
  EXPECT_FALSE(timeline.push(5 * kMs, at(2.0, 0.0)));
  EXPECT_EQ(timeline.size(), 1u);
}

TEST(PoseTimeline, AFullHistoryForgetsTheOldest) {
  PoseTimeline timeline(PoseTimelineParams{.capacity = 4});
  for (int i = 0; i < 10; ++i)
    ASSERT_TRUE(timeline.push(i * 10 * kMs, at(double(i), 0.0)));
  EXPECT_EQ(timeline.size(), 4u);
  EXPECT_FALSE(timeline.at(50 * kMs)->fresh) << "sample 5 is gone: older than the history";
  EXPECT_NEAR(timeline.at(75 * kMs)->pose.position.x, 7.5, 1e-12);
}

// pose_timeline.h: storage reserved once; push() and at() allocate nothing
// (the lens thread pushes, the render thread asks).
TEST(PoseTimeline, PushingAndAskingAllocateNothing) {
  PoseTimeline timeline(PoseTimelineParams{.capacity = 16});
  camhead::test::counting_new::start([] { return 0; });
  for (int i = 0; i < 100; ++i) { // past its capacity: the ring wraps
    (void)timeline.push(i * 10 * kMs, at(0.01 * i, 0.1 * i));
    (void)timeline.at(i * 10 * kMs - 5 * kMs);
  }
  camhead::test::counting_new::stop();
  EXPECT_EQ(camhead::test::counting_new::count(0), 0u);
}

} // namespace
} // namespace camhead::pipeline
