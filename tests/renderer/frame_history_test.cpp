// Accumulation while the camera holds still (frame_history.h): N still frames
// of one sample each are one frame of N samples, bit for bit; a change of
// focus, aperture, image scale or pose beyond the tolerance starts afresh, so
// the first frame after a jump carries nothing of the frames before it; and
// pass-through and the influence region stay exact with it on. The same for
// the GPU executor's history (every pixel alike, and reconstructed), where
// Vulkan is.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <span>
#include <vector>

#include "camhead/base/video_format.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/frame_history.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/frame_settings.h"
#include "camhead/renderer/influence_region.h"
#include "history_support.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

using namespace history;

// Both executors (the GPU's where Vulkan is).
class FrameHistoryOn : public ::testing::TestWithParam<Executor> {};

TEST_P(FrameHistoryOn, NStillFramesOfOneSampleAreOneFrameOfN) {
  const Scene scene = ball_scene();
  Frames one_at_a_time(scene, false, GetParam());
  if (!one_at_a_time.available())
    GTEST_SKIP() << "no Vulkan device";
  for (std::uint32_t n = 1; n <= 16; ++n) {
    // Each frame has its own seed, as the run loop's do: a continuing
    // history keeps its own.
    const FrameReport report = one_at_a_time.render(still_uniform(scene, 1, 100 + n));
    EXPECT_EQ(report.history_samples, n);
    EXPECT_EQ(report.history_restarted, n == 1);
    EXPECT_EQ(report.camera_rays, report.traced_pixels);
  }
  Frames at_once(scene, false, GetParam());
  const FrameReport report = at_once.render(still_uniform(scene, 16, 101));
  EXPECT_EQ(report.history_samples, 16u);
  EXPECT_EQ(bytes_differing(one_at_a_time.out(), at_once.out()), 0u);

  // In uneven steps too.
  Frames uneven(scene, false, GetParam());
  for (const std::uint32_t rpp : {3u, 1u, 7u, 5u})
    (void)uneven.render(still_uniform(scene, rpp, 101));
  EXPECT_EQ(bytes_differing(uneven.out(), at_once.out()), 0u);

  // The comparison can tell: 16 frames of a history held at one sample
  // (the same pattern, the same first sample) are not 16 samples.
  Frames one(scene, false, GetParam());
  for (int n = 0; n < 16; ++n) {
    FrameRequest request = still_uniform(scene, 1, 101);
    request.accumulation.max_samples = 1;
    (void)one.render(request);
  }
  EXPECT_GT(bytes_differing(one.out(), at_once.out()), 100u);
}

TEST_P(FrameHistoryOn, AFullHistoryTracesNothingMore) {
  const Scene scene = ball_scene();
  Frames frames(scene, false, GetParam());
  if (!frames.available())
    GTEST_SKIP() << "no Vulkan device";
  FrameRequest request = still_uniform(scene, 3);
  request.accumulation.max_samples = 8;
  EXPECT_EQ(frames.render(request).history_samples, 3u);
  EXPECT_EQ(frames.render(request).history_samples, 6u);
  const FrameReport third = frames.render(request);
  EXPECT_EQ(third.history_samples, 8u);
  EXPECT_EQ(third.camera_rays, third.traced_pixels * 2);
  const std::vector<std::uint8_t> full = frames.out();
  const FrameReport fourth = frames.render(request);
  EXPECT_EQ(fourth.history_samples, 8u);
  EXPECT_EQ(fourth.camera_rays, 0u);
  EXPECT_EQ(bytes_differing(frames.out(), full), 0u);
}

// A whole history adds no sample, and its frames take the last frame's
// reconstruction rather than making it again (bench/RESULTS.md, "A frame
// that adds no ray is not reconstructed again"): the same bytes as making
// it, and only where that frame made it as this one would. Another
// strength, or the reconstruction off and on, gives what a history made
// whole with that setting gives. (That a frame keeps it rather than makes
// it again shows in the time alone: camhead_benchmarks, live_still_capped.)
TEST_P(FrameHistoryOn, AWholeHistoryFollowsTheReconstructionsStrength) {
  const Scene scene = defocused_ball_scene();
  const auto frame_at = [](const Scene &s, double strength, bool reconstruct = true) {
    FrameRequest request = still_uniform(s, 4);
    request.accumulation.max_samples = 8;
    request.accumulation.reconstruct = reconstruct;
    request.accumulation.reconstruct_strength = strength;
    return request;
  };
  // What each setting gives a history made whole with it, by its second
  // frame: one that adds samples, and so reconstructs.
  const auto whole = [&](double strength, bool reconstruct) {
    Frames frames(scene, false, GetParam());
    for (int n = 0; n < 2; ++n)
      (void)frames.render(frame_at(scene, strength, reconstruct));
    return frames.out();
  };
  Frames frames(scene, false, GetParam());
  if (!frames.available())
    GTEST_SKIP() << "no Vulkan device";
  const std::vector<std::uint8_t> at_1 = whole(1.0, true), at_3 = whole(3.0, true),
                                  raw = whole(1.0, false);
  ASSERT_GT(bytes_differing(at_1, at_3), 100u) << "the strength must show";
  ASSERT_GT(bytes_differing(at_1, raw), 100u) << "the reconstruction must show";
  for (int n = 0; n < 3; ++n)
    (void)frames.render(frame_at(scene, 1.0));
  EXPECT_EQ(bytes_differing(frames.out(), at_1), 0u);
  EXPECT_EQ(frames.render(frame_at(scene, 3.0)).camera_rays, 0u) << "the history is whole";
  EXPECT_EQ(bytes_differing(frames.out(), at_3), 0u);
  (void)frames.render(frame_at(scene, 1.0, false));
  EXPECT_EQ(bytes_differing(frames.out(), raw), 0u);
  (void)frames.render(frame_at(scene, 1.0));
  EXPECT_EQ(bytes_differing(frames.out(), at_1), 0u);
}

// A plate-only frame (a pose not known yet: frame_renderer.h) is the camera
// image and traces nothing; the history before it ends, and the frame after
// starts one afresh, byte for byte as a new renderer's first frame.
TEST_P(FrameHistoryOn, APlateOnlyFrameEndsTheHistory) {
  const Scene scene = ball_scene();
  Frames frames(scene, false, GetParam());
  if (!frames.available())
    GTEST_SKIP() << "no Vulkan device";
  (void)frames.render(still_uniform(scene, 2));
  EXPECT_GT(bytes_differing(frames.out(), camera_frame()), 100u) << "the ball must show";
  FrameRequest plate_only = still_uniform(scene, 2);
  plate_only.plate_only = true;
  const FrameReport report = frames.render(plate_only);
  EXPECT_EQ(report.traced_pixels, 0u);
  EXPECT_EQ(report.camera_rays, 0u);
  EXPECT_EQ(report.history_samples, 0u);
  EXPECT_EQ(bytes_differing(frames.out(), camera_frame()), 0u);
  const FrameReport after = frames.render(still_uniform(scene, 2));
  EXPECT_TRUE(after.history_restarted);
  EXPECT_EQ(after.history_samples, 2u);
  // Nothing of the frames before: the same as a new renderer's first frame.
  Frames fresh(scene, false, GetParam());
  (void)fresh.render(still_uniform(scene, 2));
  EXPECT_EQ(bytes_differing(frames.out(), fresh.out()), 0u);
}

INSTANTIATE_TEST_SUITE_P(Executors, FrameHistoryOn, ::testing::Values(Executor::cpu, Executor::gpu),
                         [](const ::testing::TestParamInfo<Executor> &executor) {
                           return executor.param == Executor::cpu ? "cpu" : "gpu";
                         });

// The changes that start a history afresh, each the size of a real move.
struct Change {
  const char *name;
  void (*apply)(FrameCamera &);
  // A change of the lens alone, after which the frames before can be moved
  // into the new camera (accumulation.h, reproject; reprojection_test.cpp).
  bool lens_only;
};

// Eight frames of a held shot, then one after `change`: it starts afresh,
// and has a fresh renderer's bytes. With `reproject`, a change of the lens
// alone starts with the samples before it, moved.
void expect_the_change_starts_afresh(Executor executor, const Change &change, bool reproject) {
  const Scene scene = ball_scene();
  Frames held(scene, false, executor);
  for (int n = 0; n < 8; ++n) {
    FrameRequest request = still(scene, 1, 200 + n);
    request.accumulation.reproject = reproject;
    (void)held.render(request);
  }
  FrameRequest moved = still(scene, 2, 300);
  moved.accumulation.reproject = reproject;
  change.apply(moved.camera);
  const FrameReport report = held.render(moved);
  EXPECT_TRUE(report.history_restarted) << change.name;
  if (reproject && change.lens_only && executor == Executor::cpu) {
    EXPECT_GT(report.reprojected_samples, 0u) << change.name;
    return;
  }
  EXPECT_EQ(report.reprojected_samples, 0u) << change.name;
  EXPECT_EQ(report.history_samples, 2u) << change.name;

  Frames fresh(scene, false, executor);
  (void)fresh.render(moved);
  EXPECT_EQ(bytes_differing(held.out(), fresh.out()), 0u) << change.name;
}

class FrameHistoryChange : public ::testing::TestWithParam<Change> {};

TEST_P(FrameHistoryChange, TheFirstFrameAfterItCarriesNothingOfTheFramesBefore) {
  expect_the_change_starts_afresh(Executor::cpu, GetParam(), false);
}

TEST_P(FrameHistoryChange, WithReprojectionAMoveOfTheCameraStillCarriesNothing) {
  expect_the_change_starts_afresh(Executor::cpu, GetParam(), true);
}

const Change kChanges[] = {
    {"focus", [](FrameCamera &c) { c.focus_distance_m = 1.2f; }, true},
    {"aperture", [](FrameCamera &c) { c.f_number = 2.8f; }, true},
    {"breathing", [](FrameCamera &c) { c.projection_focal_length_mm = 50.5f; }, true},
    {"pupil", [](FrameCamera &c) { c.entrance_pupil_offset_m = 0.01f; }, false},
    {"position",
     [](FrameCamera &c) {
       c.position.x += 0.01f;
       c.look_at.x += 0.01f;
     },
     false},
    {"direction", [](FrameCamera &c) { c.look_at.x += 0.01f; }, false},
};

INSTANTIATE_TEST_SUITE_P(Changes, FrameHistoryChange, ::testing::ValuesIn(kChanges),
                         [](const ::testing::TestParamInfo<Change> &change) {
                           return change.param.name;
                         });

TEST(FrameHistory, AChangeWithinTheToleranceKeepsTheHistoryAndItsCamera) {
  const Scene scene = ball_scene();
  Frames held(scene);
  Frames steady(scene);
  for (int n = 0; n < 6; ++n) {
    FrameRequest request = still_uniform(scene, 1, 400 + n);
    (void)steady.render(request);
    // Encoder noise after the filter: a few micrometres of focus.
    request.camera.focus_distance_m += (n % 2 == 0 ? 1e-5f : -1e-5f);
    const FrameReport report = held.render(request);
    EXPECT_EQ(report.history_samples, std::uint32_t(n + 1));
  }
  EXPECT_EQ(bytes_differing(held.out(), steady.out()), 0u);
}

TEST(FrameHistory, TheToleranceIsWhereTheHistoryEnds) {
  // Focus changes that move the blur circles by 80 % and by 120 % of the
  // tolerance (found by frame_change_px, a few secant steps).
  const Scene scene = ball_scene();
  const gpu::FrameParams a = make_frame_params(scene, scene_camera(scene));
  const double nearest = nearest_depth_m(compile_scene(scene), a);
  const auto change_for = [&](double delta_m) {
    FrameCamera moved = scene_camera(scene);
    moved.focus_distance_m += float(delta_m);
    return frame_change_px(a, make_frame_params(scene, moved), nearest);
  };
  const double tolerance = AccumulationSettings{}.tolerance_px;
  for (const double fraction : {0.8, 1.2}) {
    double delta = 1e-3;
    for (int step = 0; step < 4; ++step)
      delta *= fraction * tolerance / change_for(delta);
    ASSERT_NEAR(change_for(delta), fraction * tolerance, 0.01 * tolerance);
    Frames frames(scene);
    (void)frames.render(still_uniform(scene, 1));
    FrameRequest moved = still_uniform(scene, 1);
    moved.camera.focus_distance_m += float(delta);
    EXPECT_EQ(frames.render(moved).history_restarted, fraction > 1.0) << fraction;
  }
}

TEST(FrameHistory, ANonAccumulatingFrameEndsTheHistory) {
  const Scene scene = ball_scene();
  Frames frames(scene);
  (void)frames.render(still(scene, 4));
  FrameRequest plain = still(scene, 1);
  plain.accumulation.enabled = false;
  EXPECT_EQ(frames.render(plain).history_samples, 0u);
  const FrameReport report = frames.render(still(scene, 1));
  EXPECT_TRUE(report.history_restarted);
  EXPECT_EQ(report.history_samples, 1u);
}

// The GPU executor accumulates every pixel alike (no shares by noise) and
// moves no samples through a new lens: above, FrameHistoryOn; here, a change
// starts afresh, and the history comes to the CPU reference's picture.
TEST(GpuFrameHistory, TheFirstFrameAfterAChangeCarriesNothingOfTheFramesBefore) {
  if (!Frames(ball_scene(), false, Executor::gpu).available())
    GTEST_SKIP() << "no Vulkan device";
  for (const Change &change : kChanges)
    expect_the_change_starts_afresh(Executor::gpu, change, true); // it does not reproject
}

// The GPU's history converges to the picture: 8 frames of 2 rpp come as
// close to a 64-rpp CPU reference as 16 fresh rays per pixel do, and far
// closer than one frame of 2 (a history divided by the wrong count, or one
// pattern's samples taken twice, would not).
TEST(GpuFrameHistory, ConvergesAsSixteenFreshRaysDo) {
  const Scene scene = ball_scene();
  Frames gpu(scene, false, Executor::gpu);
  if (!gpu.available())
    GTEST_SKIP() << "no Vulkan device";
  Frames reference(scene);
  FrameRequest plain = still(scene, 64);
  plain.accumulation.enabled = false;
  (void)reference.render(plain);
  Frames first(scene, false, Executor::gpu);
  (void)first.render(still_uniform(scene, 2, 101));
  for (std::uint32_t n = 1; n <= 8; ++n)
    (void)gpu.render(still_uniform(scene, 2, 100 + n));
  Frames fresh(scene, false, Executor::gpu);
  plain = still(scene, 16, 7);
  plain.accumulation.enabled = false;
  (void)fresh.render(plain);
  const double history = virtual_error(gpu, reference);
  std::printf("[ history ] GPU: error %.4f after 8 frames of 2 rpp, %.4f one frame of 2, %.4f "
              "fresh at 16\n",
              history, virtual_error(first, reference), virtual_error(fresh, reference));
  EXPECT_LT(history, 0.6 * virtual_error(first, reference));
  EXPECT_LT(history, 1.3 * virtual_error(fresh, reference));
}

// The GPU executor's history is the CPU reference's with the rays shared
// alike: the same Sobol' samples, the same reconstruction, so frame after
// frame of a defocused held shot the same picture (on lavapipe byte for
// byte), but for the last bit of a few floats that may tip a code value on
// a device whose exp and cube root are its own. Without the GPU's
// reconstruction a quarter of the bytes differ, by up to 106.
TEST(GpuFrameHistory, IsTheCpuReferencesWithTheRaysSharedAlike) {
  const Scene scene = defocused_ball_scene();
  Frames gpu(scene, false, Executor::gpu);
  if (!gpu.available())
    GTEST_SKIP() << "no Vulkan device";
  Frames cpu(scene);
  for (std::uint32_t n = 1; n <= 8; ++n) {
    const FrameRequest request = still_uniform(scene, n % 3 + 1, 900 + n);
    (void)gpu.render(request);
    (void)cpu.render(request);
    std::size_t differing = 0;
    int most = 0;
    for (std::size_t i = 0; i < cpu.out().size(); ++i) {
      const int d = std::abs(int(gpu.out()[i]) - int(cpu.out()[i]));
      differing += d != 0;
      most = std::max(most, d);
    }
    EXPECT_LE(most, 1) << "frame " << n;
    EXPECT_LT(differing, cpu.out().size() / 200) << "frame " << n;
  }
}

// For measurement the GPU executor can hand its float composite back
// (FrameRequest::keep_composite): the outputs keep their bytes, and the
// composite is the frame's picture, far closer to the CPU reference's
// converged one than the camera image alone (a plate-only frame's) is.
TEST(GpuFrameHistory, AKeptCompositeIsThePictureAndChangesNoByte) {
  const Scene scene = defocused_ball_scene();
  Frames kept(scene, false, Executor::gpu);
  if (!kept.available())
    GTEST_SKIP() << "no Vulkan device";
  Frames plain(scene, false, Executor::gpu);
  const Frames reference = converged(scene, 78);
  gpu::FrameParams frame = make_frame_params(scene, scene_camera(scene));
  frame.image.z = 1u;
  const InfluenceRegion region = influence_region(compile_scene(scene), frame);
  // Over the region: the reference's composite is set there alone.
  const auto error = [&](std::span<const glm::vec4> composite) {
    const std::span<const glm::vec4> expected = reference.composite();
    EXPECT_EQ(composite.size(), expected.size());
    double diff = 0.0, ref = 0.0;
    for (const PixelRect &r : region.rects)
      for (std::uint32_t y = r.y0; y < r.y1; ++y)
        for (std::uint32_t x = r.x0; x < r.x1; ++x)
          for (int c = 0; c < 3; ++c) {
            const std::size_t i = std::size_t(y) * kWidth + x;
            diff += (composite[i][c] - expected[i][c]) * (composite[i][c] - expected[i][c]);
            ref += expected[i][c] * expected[i][c];
          }
    return std::sqrt(diff / ref);
  };
  for (std::uint32_t n = 1; n <= 4; ++n) {
    FrameRequest request = still(scene, 4, 700 + n);
    (void)plain.render(request);
    EXPECT_TRUE(plain.composite().empty());
    request.keep_composite = true;
    (void)kept.render(request);
    EXPECT_EQ(bytes_differing(kept.out(), plain.out()), 0u) << "frame " << n;
  }
  const double picture = error(kept.composite());
  FrameRequest camera_alone = still(scene, 4, 705);
  camera_alone.plate_only = true;
  camera_alone.keep_composite = true;
  (void)kept.render(camera_alone);
  const double camera = error(kept.composite());
  std::printf(
      "[ history ] GPU composite after 16 samples: error %.4f, the camera image alone %.4f\n",
      picture, camera);
  EXPECT_LT(picture, 0.25 * camera);
}

TEST(FrameHistory, TheRegionStaysExact) {
  // Over eight accumulating frames of every pixel alike, the region gives
  // what tracing every pixel gives.
  const Scene scene = ball_scene();
  Frames region(scene);
  Frames whole(scene);
  for (int n = 0; n < 8; ++n) {
    FrameRequest request = still_uniform(scene, 1, 500 + n);
    // The reconstruction borrows from traced pixels only: more of them in
    // the whole frame (frame_history.h).
    request.accumulation.reconstruct = false;
    (void)region.render(request);
    request.influence_region = false;
    (void)whole.render(request);
    EXPECT_EQ(bytes_differing(region.out(), whole.out()), 0u) << "frame " << n;
  }
}

TEST_P(FrameHistoryOn, PixelsOutsideTheRegionPassThrough) {
  // With the rays shared by noise and a fraction of a ray more (the CPU
  // reference's: first frames and held ones past their pilot spend it) and
  // the reconstruction borrowing samples across the blur, a pixel that nothing
  // virtual touches is the camera's, byte for byte, in every frame, also
  // where the renderer resolves every pixel (a second output in another
  // format), so that what the filter leaves outside the region is read there.
  const Scene scene = defocused_ball_scene();
  Frames frames(scene, true, GetParam());
  if (!frames.available())
    GTEST_SKIP() << "no Vulkan device";
  gpu::FrameParams frame = make_frame_params(scene, scene_camera(scene));
  frame.image.z = 1u;
  const InfluenceRegion region = influence_region(compile_scene(scene), frame);
  std::vector<bool> inside(std::size_t(kWidth * kHeight), false);
  for (const PixelRect &r : region.rects)
    for (std::uint32_t y = r.y0; y < r.y1; ++y)
      for (std::uint32_t x = r.x0; x < r.x1; ++x)
        inside[std::size_t(y) * kWidth + x] = true;
  ASSERT_LT(region.pixels(), std::uint64_t(kWidth * kHeight)) << "the region must leave pixels out";
  const std::vector<std::uint8_t> plate = camera_frame();
  for (int n = 0; n < 12; ++n) {
    FrameRequest request = still(scene, 2, 600 + n);
    request.extra_rays_per_pixel = 0.5f;
    request.camera.focus_distance_m += n % 6 == 5 ? 0.05f : 0.0f; // and new histories
    (void)frames.render(request);
    std::size_t differ = 0;
    for (std::size_t p = 0; p < inside.size(); ++p)
      for (std::size_t c = 0; c < 3; ++c)
        differ += !inside[p] && frames.out()[p * 3 + c] != plate[p * 3 + c];
    EXPECT_EQ(differ, 0u) << "frame " << n;
  }
}

TEST_P(FrameHistoryOn, OneReconstructedRayPerPixelOfADefocusedShotIsNearlyNineFreshOnes) {
  // At this size the blur circles are 5-7 px; at 720x576, where the rig's
  // near focus blurs by tens of pixels, the reconstructed frame beats 9 rpp
  // (camhead bench live, bench/RESULTS.md). Each executor against its own
  // fresh frames, all against the CPU reference's converged picture.
  const Scene scene = defocused_ball_scene();
  Frames nine(scene, false, GetParam());
  if (!nine.available())
    GTEST_SKIP() << "no Vulkan device";
  const Frames reference = converged(scene, 78);
  FrameRequest fresh = still_uniform(scene, 9, 79);
  fresh.accumulation.enabled = false;
  (void)nine.render(fresh);
  Frames raw(scene, false, GetParam());
  FrameRequest one = still(scene, 1, 80);
  one.accumulation.reconstruct = false;
  (void)raw.render(one);
  Frames reconstructed(scene, false, GetParam());
  one.accumulation.reconstruct = true;
  (void)reconstructed.render(one);
  const double e9 = virtual_error(nine, reference);
  const double e1 = virtual_error(raw, reference);
  const double e1r = virtual_error(reconstructed, reference);
  std::printf("[ history ] defocused shot, %s: error %.4f at 1 rpp, %.4f reconstructed, %.4f at 9 "
              "rpp\n",
              GetParam() == Executor::cpu ? "cpu" : "gpu", e1, e1r, e9);
  EXPECT_LT(e1r, 0.25 * e1);
  EXPECT_LT(e1r, 1.5 * e9);
}

TEST(FrameHistory, SharingByNoiseConvergesFasterThanEveryPixelAlike) {
  // The same rays (2 a frame for 16 frames), given where the samples
  // disagree: the blurred rim of the ball and its shadow.
  const Scene scene = ball_scene();
  const Frames reference = converged(scene, 77);
  Frames alike(scene);
  Frames by_noise(scene);
  std::uint64_t rays_alike = 0, rays_by_noise = 0;
  for (int n = 0; n < 16; ++n) {
    FrameRequest uniform = still_uniform(scene, 2, 700 + n);
    FrameRequest shared = still(scene, 2, 700 + n);
    uniform.accumulation.reconstruct = shared.accumulation.reconstruct = false; // sharing alone
    rays_alike += alike.render(uniform).camera_rays;
    rays_by_noise += by_noise.render(shared).camera_rays;
  }
  const double e_alike = virtual_error(alike, reference);
  const double e_by_noise = virtual_error(by_noise, reference);
  std::printf("[ history ] 16 frames of 2 rpp: error %.4f every pixel alike, %.4f by noise "
              "(rays %llu, %llu)\n",
              e_alike, e_by_noise, static_cast<unsigned long long>(rays_alike),
              static_cast<unsigned long long>(rays_by_noise));
  EXPECT_LT(e_by_noise, 0.8 * e_alike);
  // The budget holds: the shares round at random, so within a few percent.
  EXPECT_NEAR(double(rays_by_noise), double(rays_alike), 0.03 * double(rays_alike));
}

// A tracked pose jitters: a turn of the view that moves no point by the
// tolerance keeps the history (and its camera), one that does ends it.
TEST(FrameHistory, ATurnWithinTheToleranceKeepsTheHistory) {
  const Scene scene = ball_scene();
  const gpu::FrameParams a = make_frame_params(scene, scene_camera(scene));
  const double nearest = nearest_depth_m(compile_scene(scene), a);
  for (const double fraction : {0.5, 2.0}) {
    // A yaw whose bound is `fraction` of the tolerance.
    const double tolerance = AccumulationSettings{}.tolerance_px;
    FrameCamera turned = scene_camera(scene);
    const auto turn = [&](double theta) {
      FrameCamera c = scene_camera(scene);
      const glm::vec3 view = c.look_at - c.position;
      c.look_at =
          c.position + glm::vec3(float(std::cos(theta)) * view.x - float(std::sin(theta)) * view.z,
                                 view.y,
                                 float(std::sin(theta)) * view.x + float(std::cos(theta)) * view.z);
      return c;
    };
    double theta = 1e-4;
    for (int step = 0; step < 4; ++step)
      theta *=
          fraction * tolerance / frame_change_px(a, make_frame_params(scene, turn(theta)), nearest);
    turned = turn(theta);
    Frames frames(scene);
    (void)frames.render(still_uniform(scene, 1));
    FrameRequest moved = still_uniform(scene, 1);
    moved.camera = turned;
    EXPECT_EQ(frames.render(moved).history_restarted, fraction > 1.0) << fraction;
  }
}

} // namespace
} // namespace camhead::renderer
