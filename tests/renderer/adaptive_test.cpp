// Adaptive ray budget per pixel (renderer/include/camhead/renderer/adaptive.h):
// the allocation, the two executors' agreement, and the quality claim.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/scene_loader.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::AdaptiveSampling;

std::uint64_t sum(const std::vector<std::uint32_t> &counts) {
  return std::accumulate(counts.begin(), counts.end(), std::uint64_t(0));
}

// How far the total of the shares may stray from the budget (adaptive.glsl):
// each share is rounded at random, one Bernoulli draw of variance <= 1/4 per
// pixel (four standard deviations allowed), and the water level is found on
// a histogram whose bins place their weights to 1/256 of a bin of 4.4 %
// (0.05 % of the budget allowed).
double budget_tolerance(std::size_t pixels, double budget) {
  return 4.0 * 0.5 * std::sqrt(double(pixels)) + 5e-4 * budget;
}

void expect_near_budget(std::uint64_t total, std::size_t pixels, std::uint64_t budget) {
  EXPECT_NEAR(double(total), double(budget), budget_tolerance(pixels, double(budget)))
      << "shares add up to " << total << " of a budget of " << budget;
}

renderer::Scene reference_scene(const std::string &name, int divisor) {
  return test::downscaled(renderer::load_scene(test::reference_dir() / (name + ".json")), divisor);
}

TEST(AdaptiveAllocation, NoisyPixelsGetMoreAndTheTotalIsTheBudgetInExpectation) {
  renderer::gpu::FrameParams frame{};
  frame.image = {16u, 8u, 0u, 0u};
  frame.sampling = {0u, 9u, 9u, 1u};
  frame.lens = {0.0f, 1.0f, 16.0f, 1.0f}; // pinhole: no circle of confusion
  const std::uint32_t pilot = 2;
  std::vector<glm::vec4> aux(16 * 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      // Left half: both pilot samples 0.5; right half: 0 and 1.
      const bool noisy = x >= 8;
      aux[y * 16 + x] = glm::vec4(2.0f, 2.0f, 1.0f, noisy ? 1.0f : 0.5f);
    }
  const auto counts = renderer::allocate_samples(aux, frame, pilot, AdaptiveSampling{});
  expect_near_budget(sum(counts), counts.size(), 16u * 8u * 9u);
  for (int y = 0; y < 8; ++y) {
    EXPECT_EQ(counts[y * 16 + 0], pilot) << "a quiet pixel away from the noise gets the pilot";
    EXPECT_GT(counts[y * 16 + 15], 9u);
    EXPECT_GE(counts[y * 16 + 15], counts[y * 16 + 0]);
  }
  EXPECT_EQ(renderer::allocate_samples(aux, frame, pilot, AdaptiveSampling{}), counts);
}

TEST(AdaptiveAllocation, PilotLeavesRaysToShare) {
  EXPECT_EQ(renderer::adaptive_pilot(AdaptiveSampling{}, 1), 1u);
  EXPECT_EQ(renderer::adaptive_pilot(AdaptiveSampling{}, 4), 1u);
  EXPECT_EQ(renderer::adaptive_pilot(AdaptiveSampling{}, 12), 3u);
  EXPECT_EQ(renderer::adaptive_pilot(AdaptiveSampling{}, 49), 4u);
}

class Adaptive : public ::testing::TestWithParam<std::string> {};

// The shares on a reference scene: the budget, at least the pilot and at
// most the cap everywhere, and the mean share in and out of focus printed.
TEST_P(Adaptive, SharesAddUpToTheBudget) {
  constexpr int rpp = 16;
  const renderer::Scene scene = reference_scene(GetParam(), 8);
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, rpp);
  const renderer::RenderResult r =
      renderer::render_cpu_adaptive(renderer::compile_scene(scene), frame);
  ASSERT_TRUE(test::all_finite(r.composite));
  ASSERT_TRUE(test::all_finite(r.mask));
  const std::size_t pixels = r.composite.pixel_count();
  ASSERT_EQ(r.sample_counts.size(), pixels);
  expect_near_budget(sum(r.sample_counts), pixels, std::uint64_t(pixels) * rpp);
  std::printf("%s: %llu samples given out of a budget of %llu\n", GetParam().c_str(),
              static_cast<unsigned long long>(sum(r.sample_counts)),
              static_cast<unsigned long long>(pixels * rpp));
  EXPECT_EQ(r.camera_rays, sum(r.sample_counts));
  const std::uint32_t pilot = renderer::adaptive_pilot(AdaptiveSampling{}, rpp);
  const std::uint32_t cap = std::uint32_t(AdaptiveSampling{}.max_factor * rpp);
  double sharp = 0.0, blurred = 0.0;
  int sharp_n = 0, blurred_n = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    EXPECT_GE(r.sample_counts[i], pilot);
    EXPECT_LE(r.sample_counts[i], cap);
    const float z = r.depth.data[i];
    const double coc_px =
        z > 0.0f ? frame.lens.x * frame.lens.z * std::abs(1.0 / z - 1.0 / frame.lens.y) : 1e9;
    if (coc_px < 0.5) {
      sharp += r.sample_counts[i];
      ++sharp_n;
    } else if (coc_px > 2.0) {
      blurred += r.sample_counts[i];
      ++blurred_n;
    }
  }
  // How much of a SIMD machine the shares keep busy: a group of lanes runs
  // as long as its largest share (8 lanes: a row of a tile on lavapipe with
  // AVX2; 32: 8x4 pixels, an NVIDIA warp of the 8x8 workgroup), and in the
  // order of the GPU's second pass, by share (sample_queue.glsl).
  const int width = r.composite.width, height = r.composite.height;
  std::vector<std::uint32_t> by_share = r.sample_counts;
  std::sort(by_share.begin(), by_share.end(), std::greater<>());
  for (const auto &[gx, gy] : {std::pair{8, 1}, std::pair{8, 4}}) {
    double busy = 0.0;
    for (int y0 = 0; y0 < height; y0 += gy)
      for (int x0 = 0; x0 < width; x0 += gx) {
        std::uint32_t most = 0;
        for (int y = y0; y < std::min(y0 + gy, height); ++y)
          for (int x = x0; x < std::min(x0 + gx, width); ++x)
            most = std::max(most, r.sample_counts[std::size_t(y) * width + x]);
        busy += double(most) * gx * gy;
      }
    double queue_busy = 0.0;
    for (std::size_t first = 0; first < by_share.size(); first += std::size_t(gx * gy))
      queue_busy += double(by_share[first]) * gx * gy; // the group's largest
    std::printf("%s: %d-lane groups busy %.0f%% of the time in %dx%d tiles, %.0f%% by share\n",
                GetParam().c_str(), gx * gy, 100.0 * double(sum(r.sample_counts)) / busy, gx, gy,
                100.0 * double(sum(r.sample_counts)) / queue_busy);
  }
  std::printf("%s: mean share in focus (CoC < 0.5 px) %.1f over %d px, defocused (> 2 px) %.1f "
              "over %d px, largest %u\n",
              GetParam().c_str(), sharp / std::max(sharp_n, 1), sharp_n,
              blurred / std::max(blurred_n, 1), blurred_n,
              *std::max_element(r.sample_counts.begin(), r.sample_counts.end()));
  // Not asserted: which pixels get more. On the reference scenes the
  // in-focus pixels do (their shadows and edges are noisy; the lens averages
  // the defocused ones into smooth, low-variance regions).
  EXPECT_GT(sharp_n + blurred_n, 0);
}

// As executors_test.cpp for the uniform path: the GPU tracer runs the same
// three steps on the same samples.
TEST_P(Adaptive, GpuAgreesWithCpuReferenceBelowSamplingNoise) {
  CAMHEAD_REQUIRE_VULKAN();
  constexpr int rpp = 16;
  renderer::Scene scene = reference_scene(GetParam(), 8);
  const renderer::CompiledScene compiled = renderer::compile_scene(scene);
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, rpp);
  renderer::GpuTracer tracer;
  tracer.load(compiled);
  const renderer::RenderResult gpu = tracer.render_adaptive(frame);
  const renderer::RenderResult cpu = renderer::render_cpu_adaptive(compiled, frame);
  renderer::gpu::FrameParams other = frame;
  other.sampling.w += 1;
  const renderer::RenderResult cpu_other = renderer::render_cpu_adaptive(compiled, other);
  ASSERT_TRUE(test::all_finite(gpu.composite));
  // The GPU counts the rays it gave out as it gives them (a 64-bit atomic
  // sum), also when the shares are not read back.
  EXPECT_EQ(gpu.camera_rays, sum(gpu.sample_counts));
  EXPECT_EQ(
      tracer.render_adaptive(frame, {}, {}, renderer::LayerSelection::display_only()).camera_rays,
      gpu.camera_rays);
  expect_near_budget(sum(gpu.sample_counts), gpu.sample_counts.size(),
                     std::uint64_t(gpu.sample_counts.size()) * rpp);
  std::size_t same = 0;
  for (std::size_t i = 0; i < gpu.sample_counts.size(); ++i)
    same += gpu.sample_counts[i] == cpu.sample_counts[i] ? 1u : 0u;
  const double noise = test::rmse(cpu.composite, cpu_other.composite) / std::sqrt(2.0);
  const double difference = test::rmse(cpu.composite, gpu.composite);
  std::printf("%s adaptive at %d rpp: GPU vs CPU RMSE %.2e, sampling noise %.2e, equal shares "
              "%zu of %zu pixels\n",
              GetParam().c_str(), rpp, difference, noise, same, gpu.sample_counts.size());
  // The same arithmetic in the same order (adaptive.glsl), but on pilots
  // that differ in the last bits and with transcendentals that may round
  // differently: a share on the edge of a rounding step may differ by one.
  EXPECT_GT(double(same), 0.99 * double(gpu.sample_counts.size()));
  EXPECT_LT(difference, noise);
}

// A wall and a ball, both virtual, filling the view, under an area light:
// every camera ray meets a virtual surface, so each pixel's mask is the
// fraction of its share that was traced. The ball's soft shadow and the
// defocus spread the shares from the pilot to the cap.
renderer::Scene virtual_wall_in_soft_shadow() {
  renderer::Scene scene;
  scene.source = "virtual_wall_in_soft_shadow";
  scene.render.width = 48;
  scene.render.height = 32;
  scene.camera.position = {0.0f, 0.0f, 0.0f};
  scene.camera.look_at = {0.0f, 0.0f, -1.0f};
  scene.camera.f_number = 2.0f;
  scene.camera.focus_distance_m = 2.0f;
  scene.materials = {{"white", renderer::MaterialType::diffuse, glm::vec3(0.8f), 1.5f, {}}};
  renderer::Object wall;
  wall.name = "wall";
  wall.type = renderer::ShapeType::plane;
  wall.center = {0.0f, 0.0f, -3.0f};
  wall.size = {20.0f, 1.0f, 20.0f};
  wall.rotation_deg = {90.0f, 0.0f, 0.0f}; // facing the camera
  renderer::Object ball;
  ball.name = "ball";
  ball.type = renderer::ShapeType::sphere;
  ball.center = {0.2f, 0.1f, -2.2f};
  ball.radius = 0.3f;
  scene.objects = {wall, ball};
  renderer::Light panel;
  panel.name = "panel";
  panel.type = renderer::LightType::area;
  panel.position = {0.0f, 1.5f, -1.2f};
  panel.normal = glm::normalize(glm::vec3(0.0f, -1.0f, -0.5f));
  panel.size = {0.8f, 0.8f};
  panel.power_W = 200.0f;
  scene.lights = {panel};
  return scene;
}

// The second pass takes its pixels from a queue ordered by share
// (sample_queue.glsl), in batches that start wherever the batch sizer puts
// them. Each pixel must be traced for exactly its share: none left out of
// the queue or cut short at a batch or bin boundary, none traced twice. The
// mask of a pixel all of whose rays meet virtual surfaces counts that,
// whatever the image: mask x share = the samples traced. Bins of one share
// (cap - pilot < QUEUE_BINS) and of three (a mean of 160, a cap 64 times it);
// the whole frame, and a region of two rectangles away from its corner
// (whose dispatches set a base that the queue's must not inherit).
TEST(AdaptiveSecondPass, TracesEachPixelsShareExactlyOnce) {
  CAMHEAD_REQUIRE_VULKAN();
  const renderer::Scene scene = virtual_wall_in_soft_shadow();
  const renderer::CompiledScene compiled = renderer::compile_scene(scene);
  renderer::GpuTracer tracer;
  tracer.load(compiled);
  const renderer::InfluenceRegion part{
      .width = 48,
      .height = 32,
      .rects = {{.x0 = 8, .y0 = 8, .x1 = 40, .y1 = 16}, {.x0 = 16, .y0 = 16, .x1 = 48, .y1 = 32}}};
  for (const auto &[rpp, max_factor] : {std::pair{12, 16.0f}, std::pair{160, 64.0f}})
    for (const renderer::InfluenceRegion *region :
         std::array<const renderer::InfluenceRegion *, 2>{nullptr, &part}) {
      AdaptiveSampling settings;
      settings.max_factor = max_factor;
      const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, rpp);
      // Twice: the first frame's batches start at one sample, the second's
      // are as large as the first measured.
      for (int repeat = 0; repeat < 2; ++repeat) {
        const renderer::RenderResult r = tracer.render_adaptive(frame, settings, {}, {}, region);
        ASSERT_EQ(r.sample_counts.size(), r.mask.pixel_count());
        std::vector<std::uint32_t> distinct = r.sample_counts;
        std::sort(distinct.begin(), distinct.end());
        distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
        std::printf("%d rpp, cap %.0fx: %zu distinct shares from %u to %u\n", rpp, max_factor,
                    distinct.size(), distinct.front(), distinct.back());
        // Else the queue would not be put to the test.
        EXPECT_GT(distinct.size(), 20u);
        EXPECT_GT(distinct.back(), 3u * std::uint32_t(rpp));
        int wrong = 0;
        for (std::size_t i = 0; i < r.sample_counts.size(); ++i) {
          const double share = r.sample_counts[i];
          const double traced = double(r.mask.data[i]) * share;
          if (std::abs(traced - share) >= 0.5 && ++wrong <= 5)
            ADD_FAILURE() << "pixel " << i % 48 << "," << i / 48 << ": " << traced
                          << " samples traced of a share of " << share;
        }
        EXPECT_EQ(wrong, 0);
      }
    }
}

// A device may stop a shader invocation's loops after so many iterations
// (lavapipe: 65535 of all its loops together, vulkan_context.h,
// max_samples_per_dispatch), silently leaving the rest of its samples
// untraced. On a frame this small the batch sizer soon gives one dispatch
// thousands of samples a pixel, uniform or in the adaptive second pass
// (whose shares here reach thousands); every camera ray meets the wall, so
// the mask of a pixel is 1 (to rounding) when every one of its samples was
// traced.
// Without the bound, lavapipe left every pixel short uniform and 23 of 64
// adaptive (the largest share 6445).
TEST(GpuBatches, EverySampleOfALongBatchIsTraced) {
  CAMHEAD_REQUIRE_VULKAN();
  renderer::Scene scene = virtual_wall_in_soft_shadow();
  scene.render.width = 8;
  scene.render.height = 8;
  const renderer::CompiledScene compiled = renderer::compile_scene(scene);
  renderer::GpuTracer tracer;
  tracer.load(compiled);
  // One sample short of a share of at most 40000 takes 2.5e-5 off the mask;
  // the resolve's division rounds by 6e-8.
  const auto untraced = [](const renderer::RenderResult &r) {
    int pixels = 0;
    for (const float m : r.mask.data)
      pixels += m < 1.0f - 1e-5f ? 1 : 0;
    return pixels;
  };
  const renderer::RenderResult uniform = tracer.render(renderer::make_frame_params(scene, 40000));
  EXPECT_EQ(untraced(uniform), 0) << "of 64 pixels at 40000 samples, uniform";
  const renderer::RenderResult adaptive =
      tracer.render_adaptive(renderer::make_frame_params(scene, 2500));
  EXPECT_GT(*std::max_element(adaptive.sample_counts.begin(), adaptive.sample_counts.end()), 4000u);
  EXPECT_EQ(untraced(adaptive), 0) << "of 64 pixels, adaptive";
}

// The quality claim at small scale: relative RMSE against a converged
// reference at equal total rays, uniform and adaptive, and the adaptive
// budget that matches uniform 49 rpp.
TEST_P(Adaptive, LowerErrorThanUniformAtEqualRays) {
  const renderer::Scene scene = reference_scene(GetParam(), 16);
  const renderer::CompiledScene compiled = renderer::compile_scene(scene);
  renderer::gpu::FrameParams ref_frame = renderer::make_frame_params(scene, 1024);
  ref_frame.sampling.w += 1000; // independent of the renders measured
  const renderer::Image reference = renderer::render_cpu(compiled, ref_frame).composite;
  const auto error = [&](int rpp, bool adaptive) {
    const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, rpp);
    const renderer::RenderResult r = adaptive ? renderer::render_cpu_adaptive(compiled, frame)
                                              : renderer::render_cpu(compiled, frame);
    return test::relative_rmse(reference, r.composite);
  };
  const double uniform49 = error(49, false);
  const double adaptive49 = error(49, true);
  int matching = 0;
  for (const int rpp : {4, 6, 8, 12, 16, 25, 36, 49}) {
    const double e = error(rpp, true);
    std::printf("%s %dx%d: adaptive %2d rpp rel. RMSE %.4f (uniform 49: %.4f)\n",
                GetParam().c_str(), scene.render.width, scene.render.height, rpp, e, uniform49);
    if (matching == 0 && e <= uniform49)
      matching = rpp;
  }
  std::printf("%s: uniform 49 rpp %.4f, adaptive 49 rpp %.4f; adaptive matches uniform 49 at %d "
              "rpp (%.1fx fewer rays)\n",
              GetParam().c_str(), uniform49, adaptive49, matching,
              matching > 0 ? 49.0 / matching : 0.0);
  EXPECT_LT(adaptive49, uniform49);
}

INSTANTIATE_TEST_SUITE_P(ReferenceScenes, Adaptive, ::testing::Values("boxes", "ar_basic"));

} // namespace
} // namespace camhead
