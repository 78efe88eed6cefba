// FrameBudget (frame_budget.h) against a made-up device whose frame costs
// overhead + rpp x cost per rpp, with noise: it must fill the target without
// running over it, and follow the scene when the cost changes.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>

#include "camhead/renderer/frame_budget.h"
#include "camhead/renderer/frame_renderer.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::FrameBudget;
using renderer::FrameBudgetSettings;

// Frame time of the made-up device, with +-4 % deterministic noise.
struct Device {
  double overhead_s = 0.0005;
  double per_rpp_s = 0.0004;
  std::uint32_t frame = 0;
  double run(std::uint32_t rpp) {
    const double noise = 0.04 * std::sin(double(frame++) * 2.3999632);
    return (overhead_s + per_rpp_s * rpp) * (1.0 + noise);
  }
};

// Runs `frames` frames; returns the largest frame time of the last `tail`.
double run_frames(FrameBudget &budget, Device &device, int frames, int tail, double *smallest) {
  double largest = 0.0;
  *smallest = 1e30;
  for (int i = 0; i < frames; ++i) {
    const std::uint32_t rpp = budget.rpp();
    const double t = device.run(rpp);
    budget.measured(rpp, t);
    if (i >= frames - tail) {
      largest = std::max(largest, t);
      *smallest = std::min(*smallest, t);
    }
  }
  return largest;
}

TEST(FrameBudget, FillsTheTargetWithoutRunningOver) {
  FrameBudget budget(FrameBudgetSettings{.target_s = 0.020});
  Device device;
  double smallest = 0.0;
  const double largest = run_frames(budget, device, 40, 20, &smallest);
  std::printf("settled at %u rpp: frames %.2f-%.2f ms for a 20 ms target\n", budget.rpp(),
              smallest * 1e3, largest * 1e3);
  EXPECT_LE(largest, 0.020);
  EXPECT_GE(smallest, 0.75 * 0.020);
}

TEST(FrameBudget, FollowsTheSceneWhenItGetsDearerOrCheaper) {
  FrameBudget budget(FrameBudgetSettings{.target_s = 0.020});
  Device device;
  double smallest = 0.0;
  run_frames(budget, device, 40, 1, &smallest);
  const std::uint32_t settled = budget.rpp();

  device.per_rpp_s *= 3.0; // a wider aperture, say
  const double late = device.run(budget.rpp());
  budget.measured(budget.rpp(), late);
  const double next = device.run(budget.rpp());
  budget.measured(budget.rpp(), next);
  std::printf("3x dearer: one frame at %.1f ms, the next at %.1f ms (%u -> %u rpp)\n", late * 1e3,
              next * 1e3, settled, budget.rpp());
  EXPECT_GT(late, 0.020) << "the first frame after the change cannot know it";
  EXPECT_LE(next, 0.020) << "the one after it must";

  device.per_rpp_s /= 9.0; // 3x cheaper than at first
  const double largest = run_frames(budget, device, 40, 40, &smallest);
  std::printf("then 3x cheaper than at first: %u rpp, no frame over %.1f ms\n", budget.rpp(),
              largest * 1e3);
  EXPECT_LE(largest, 0.020) << "growing back must not overshoot";
  EXPECT_GT(budget.rpp(), 2 * settled);
}

TEST(FrameBudget, ScalesOnlyTheRaysTimeWithTheRays) {
  // A frame whose fixed part (the camera frame in and out, the
  // reconstruction) is 8 ms and whose rays take 12 ms a ray a pixel: 2 rpp
  // take 32 ms and fit 36 ms (a 40-ms frame's 0.9). Told the rays' time,
  // the budget gives them; taking the whole frame as the rays', it finds
  // 20 ms a ray a pixel and keeps 1.
  Device device{.overhead_s = 0.008, .per_rpp_s = 0.012};
  FrameBudget apart(FrameBudgetSettings{.target_s = 0.040});
  FrameBudget all(FrameBudgetSettings{.target_s = 0.040});
  double largest = 0.0;
  for (int i = 0; i < 30; ++i) {
    const double rays = device.per_rpp_s * apart.rpp();
    const double t = device.overhead_s + rays;
    apart.measured(apart.rpp(), t, rays);
    all.measured(all.rpp(), device.overhead_s + device.per_rpp_s * all.rpp());
    if (i > 0)
      largest = std::max(largest, t);
  }
  EXPECT_EQ(apart.rpp(), 2u);
  EXPECT_LE(largest, 0.036);
  EXPECT_EQ(all.rpp(), 1u);
  // A frame not told apart after them counts whole, with no fixed part
  // taken off it again: 16 ms a ray a pixel, 2 rpp still fit.
  apart.measured(2.0, device.overhead_s + 2.0 * device.per_rpp_s);
  EXPECT_EQ(apart.rpp(), 2u);
}

TEST(FrameBudget, GivesTheFractionOfARayThatFits) {
  // 8 ms fixed and 12 ms a ray a pixel: 2 whole rays fit 36 ms (0.9 of 40),
  // and a fraction more 34 ms (0.85): 2.17 rays a pixel, in sixteenths 2
  // and 2/16.
  Device device{.overhead_s = 0.008, .per_rpp_s = 0.012};
  FrameBudget budget(FrameBudgetSettings{.target_s = 0.040});
  for (int i = 0; i < 30; ++i) {
    const double rays = device.per_rpp_s * budget.rays_per_pixel();
    budget.measured(budget.rays_per_pixel(), device.overhead_s + rays, rays);
  }
  EXPECT_DOUBLE_EQ(budget.rays_per_pixel(), 2.0 + 2.0 / 16.0);
  EXPECT_EQ(budget.rpp(), 2u);
  // At 13.5 ms a ray, 2 whole rays fit 36 ms (2.07); within 34 ms only 1.93
  // would, 1.875 in sixteenths: the whole rays stay.
  Device dearer{.overhead_s = 0.008, .per_rpp_s = 0.0135};
  FrameBudget whole(FrameBudgetSettings{.target_s = 0.040});
  for (int i = 0; i < 30; ++i) {
    const double rays = dearer.per_rpp_s * whole.rays_per_pixel();
    whole.measured(whole.rays_per_pixel(), dearer.overhead_s + rays, rays);
  }
  EXPECT_DOUBLE_EQ(whole.rays_per_pixel(), 2.0);
}

TEST(FrameBudget, AMeanOfRaysIsSplitIntoWholeRaysAndAFractionBelowOne) {
  renderer::FrameRequest request;
  renderer::set_mean_rays_per_pixel(request, 2.0 + 5.0 / 16.0 + 0.01);
  EXPECT_EQ(request.rays_per_pixel, 2u);
  EXPECT_EQ(request.extra_rays_per_pixel, 5.0f / 16.0f);
  renderer::set_mean_rays_per_pixel(request, 1.99999999);
  EXPECT_EQ(request.rays_per_pixel, 1u);
  EXPECT_EQ(request.extra_rays_per_pixel, 15.0f / 16.0f);
  for (const double bad : {0.5, -3.0, std::nan("")}) {
    renderer::set_mean_rays_per_pixel(request, bad);
    EXPECT_EQ(request.rays_per_pixel, 1u) << bad;
    EXPECT_EQ(request.extra_rays_per_pixel, 0.0f) << bad;
  }
}

TEST(FrameBudget, StaysWithinItsRange) {
  FrameBudget fast(FrameBudgetSettings{.target_s = 1.0, .max_rpp = 64});
  Device device;
  double smallest = 0.0;
  run_frames(fast, device, 30, 1, &smallest);
  EXPECT_EQ(fast.rpp(), 64u);

  FrameBudget slow(FrameBudgetSettings{.target_s = 0.0001, .min_rpp = 4});
  run_frames(slow, device, 10, 1, &smallest);
  EXPECT_EQ(slow.rpp(), 4u) << "a device too slow for the target still gets the minimum";
  slow.measured(4, -1.0);
  slow.measured(0, 0.01);
  EXPECT_EQ(slow.rpp(), 4u);
}

TEST(FrameBudget, RejectsAnEmptyRangeNoTargetOrNoHeadroom) {
  EXPECT_THROW(FrameBudget(FrameBudgetSettings{.target_s = 0.0}), std::invalid_argument);
  EXPECT_THROW(FrameBudget(FrameBudgetSettings{.min_rpp = 8, .max_rpp = 4}), std::invalid_argument);
  EXPECT_THROW(FrameBudget(FrameBudgetSettings{.min_rpp = 0}), std::invalid_argument);
  EXPECT_THROW(FrameBudget(FrameBudgetSettings{.headroom = 0.0}), std::invalid_argument);
  EXPECT_THROW(FrameBudget(FrameBudgetSettings{.headroom = 0.8, .fraction_headroom = 0.85}),
               std::invalid_argument);
}

} // namespace
} // namespace camhead
