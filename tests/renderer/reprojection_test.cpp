// A new history's first samples, moved from the frames before through the new
// lens (accumulation.h, reproject; renderer/src/sample_store.h). The frame
// after a focus jump must have a fresh render's expected value, nothing of
// the old focus (no ghost), and less noise than a fresh frame; a pull frame
// must come closer to the reference than one that starts afresh.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <vector>

#include <glm/vec4.hpp>

#include "camhead/renderer/frame_renderer.h"
#include "history_support.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

using namespace history;

// Relative RMSE of `image` against `reference`, linear RGB, every pixel.
double error(std::span<const glm::vec4> image, std::span<const glm::vec4> reference) {
  double diff = 0.0, ref = 0.0;
  for (std::size_t i = 0; i < reference.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double a = reference[i][c], b = image[i][c];
      diff += (a - b) * (a - b);
      ref += a * a;
    }
  return std::sqrt(diff / ref);
}

// The mean of many frames' composites.
class Mean {
public:
  void add(std::span<const glm::vec4> image) {
    sum_.resize(image.size(), glm::vec4(0.0f));
    for (std::size_t i = 0; i < image.size(); ++i)
      sum_[i] += image[i];
    ++n_;
  }
  [[nodiscard]] std::vector<glm::vec4> mean() const {
    std::vector<glm::vec4> m = sum_;
    for (glm::vec4 &v : m)
      v /= float(n_);
    return m;
  }

private:
  std::vector<glm::vec4> sum_;
  int n_ = 0;
};

// Before the jump: the ball scene's own focus (2 m, f/2). After: focused
// at 0.6 m, stopped down to f/2.8, the image scale breathing by 3 %: at
// this size a blur circle grows or shrinks by up to a pixel, and the frame's
// edges move by one.
// Either lens: the ideal one, or a strong barrel with its principal point
// off centre, through which samples land by the lens's distortion
// (renderer/src/sample_store.h).
LensModel lens_of(bool distorted) {
  LensModel lens;
  if (distorted) {
    lens.k1 = -0.25f;
    lens.k2 = 0.05f;
    lens.p1 = 0.004f;
    lens.principal_point = {0.53f, 0.47f};
  }
  return lens;
}

FrameCamera before_the_jump(const Scene &scene, bool distorted) {
  FrameCamera camera = scene_camera(scene);
  camera.lens_model = lens_of(distorted);
  return camera;
}

FrameCamera after_the_jump(const Scene &scene, bool distorted) {
  FrameCamera camera = before_the_jump(scene, distorted);
  camera.focus_distance_m = 0.6f;
  camera.f_number = 2.8f;
  camera.projection_focal_length_mm = 1.03f * camera.focal_length_mm;
  return camera;
}

FrameRequest frame(const Scene &scene, const FrameCamera &camera, std::uint32_t seed) {
  FrameRequest request = still_uniform(scene, 1, seed);
  request.camera = camera;
  request.accumulation.reconstruct = false; // the samples alone
  return request;
}

// Through the ideal lens and through a distorting one.
class Reprojection : public ::testing::TestWithParam<bool> {};

TEST_P(Reprojection, TheFrameAfterAFocusJumpHasAFreshFramesExpectedValue) {
  const Scene scene = ball_scene();
  const FrameCamera before = before_the_jump(scene, GetParam());
  const FrameCamera jumped = after_the_jump(scene, GetParam());
  Frames reference(scene);
  {
    FrameRequest request = still_uniform(scene, 1024, 9);
    request.camera = jumped;
    request.accumulation.max_samples = 1024;
    (void)reference.render(request);
  }
  const std::vector<glm::vec4> truth(reference.composite().begin(), reference.composite().end());

  // Many trials: eight frames held at the first focus, then the jump, with
  // the frames before moved and without (afresh). If the moved samples are
  // unbiased, the mean of the frames after the jump converges to the new
  // focus's picture as noise does, its error halving for four times the
  // trials; a ghost of the old focus (a history kept across the jump, the
  // negative control) stays.
  constexpr int kTrials = 64;
  Mean jump, jump_quarter, ghost, ghost_quarter;
  double e_one = 0.0, e_afresh = 0.0; // single frames, mean over the trials
  std::uint64_t samples = 0;
  for (int t = 0; t < kTrials; ++t) {
    Frames moved(scene), afresh(scene), kept(scene);
    for (int n = 0; n < 8; ++n) {
      FrameRequest request = frame(scene, before, 1000u * t + n);
      (void)moved.render(request);
      (void)kept.render(request);
      request.accumulation.reproject = false;
      (void)afresh.render(request);
    }
    FrameRequest after = frame(scene, jumped, 1000u * t + 500);
    const FrameReport report = moved.render(after);
    EXPECT_TRUE(report.history_restarted);
    EXPECT_GT(report.reprojected_samples, 0u);
    samples += report.history_samples;
    jump.add(moved.composite());
    e_one += error(moved.composite(), truth) / kTrials;
    after.accumulation.tolerance_px = 1e9; // keeps the history of the old focus
    (void)kept.render(after);
    ghost.add(kept.composite());
    after.accumulation.tolerance_px = AccumulationSettings{}.tolerance_px;
    after.accumulation.reproject = false;
    (void)afresh.render(after);
    e_afresh += error(afresh.composite(), truth) / kTrials;
    if (t < kTrials / 4) {
      jump_quarter.add(moved.composite());
      ghost_quarter.add(kept.composite());
    }
  }
  const double e_jump = error(jump.mean(), truth);
  const double e_jump_quarter = error(jump_quarter.mean(), truth);
  const double e_ghost = error(ghost.mean(), truth);
  const double e_ghost_quarter = error(ghost_quarter.mean(), truth);
  std::printf(
      "[ reproject ] %s lens, focus jump: a frame's error %.4f (%.1f samples a pixel held), "
      "%.4f afresh; the mean of %d / %d frames %.4f / %.4f (%.2fx), of the old focus "
      "kept %.4f / %.4f (%.2fx)\n",
      GetParam() ? "distorting" : "ideal", e_one, double(samples) / kTrials, e_afresh, kTrials / 4,
      kTrials, e_jump_quarter, e_jump, e_jump_quarter / e_jump, e_ghost_quarter, e_ghost,
      e_ghost_quarter / e_ghost);
  EXPECT_GE(samples / kTrials, 2u) << "the jump's frames hold more than their own ray";
  EXPECT_LT(e_one, 0.8 * e_afresh);
  // Unbiased: the mean converges as noise does (2x; a bias would hold it).
  EXPECT_GT(e_jump_quarter / e_jump, 1.6);
  // The measure can tell a ghost.
  EXPECT_LT(e_ghost_quarter / e_ghost, 1.2);
  EXPECT_GT(e_ghost, 4.0 * e_jump);
}

TEST_P(Reprojection, APullFrameComesCloserToItsPictureThanOneStartedAfresh) {
  // Twelve frames of a pull from the scene's focus (2 m) to 0.6 m, even in
  // diopters, one ray per pixel each, as camhead run renders them; the last
  // against a converged render of its own lens.
  const Scene scene = ball_scene();
  const FrameCamera end = after_the_jump(scene, GetParam());
  const FrameCamera start = before_the_jump(scene, GetParam());
  const auto at = [&](int k) {
    FrameCamera camera = end;
    const float w0 = 1.0f / start.focus_distance_m, w1 = 1.0f / end.focus_distance_m;
    camera.focus_distance_m = 1.0f / (w0 + (w1 - w0) * float(k) / 11.0f);
    camera.f_number = end.f_number;
    return camera;
  };
  Frames reference(scene);
  FrameRequest request = still_uniform(scene, 1024, 9);
  request.camera = at(11);
  request.accumulation.max_samples = 1024;
  (void)reference.render(request);
  const std::vector<glm::vec4> truth(reference.composite().begin(), reference.composite().end());

  // [reconstructed][reprojected], the mean over a few trials.
  double e[2][2] = {{0.0, 0.0}, {0.0, 0.0}};
  constexpr int kTrials = 4;
  for (int t = 0; t < kTrials; ++t)
    for (const bool reconstruct : {false, true})
      for (const bool reproject : {false, true}) {
        Frames frames(scene);
        for (int k = 0; k < 12; ++k) {
          FrameRequest pull = still(scene, 1, 100u * t + k);
          pull.camera = at(k);
          pull.accumulation.reconstruct = reconstruct;
          pull.accumulation.reproject = reproject;
          (void)frames.render(pull);
        }
        e[reconstruct][reproject] += error(frames.composite(), truth) / kTrials;
      }
  std::printf(
      "[ reproject ] %s lens, pull frame: error %.4f afresh, %.4f with the frames before moved; "
      "reconstructed %.4f, %.4f\n",
      GetParam() ? "distorting" : "ideal", e[0][0], e[0][1], e[1][0], e[1][1]);
  // The samples alone: six frames' more (the store holds six of this
  // region), independent rather than one pattern's, so less than 7 rpp's gain.
  EXPECT_LT(e[0][1], 0.6 * e[0][0]);
  // With the reconstruction, which does most of the work at this blur.
  EXPECT_LT(e[1][1], e[1][0]);
}

INSTANTIATE_TEST_SUITE_P(Lenses, Reprojection, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool> &lens) {
                           return lens.param ? "Distorted" : "Ideal";
                         });

TEST(Reprojection, KeepingAFramesSamplesChangesNothingInIt) {
  // A frame whose samples are kept traces them through the renderer's own
  // loop (cpu_frame_renderer.cpp, trace_and_keep), which must trace what
  // the kernel's trace_pixel() does: held frames with reprojection on and
  // off give the same composite, bit for bit.
  const Scene scene = ball_scene();
  Frames kept(scene), plain(scene);
  for (int n = 0; n < 3; ++n) {
    FrameRequest request = still_uniform(scene, 2, 60u + std::uint32_t(n));
    (void)kept.render(request);
    request.accumulation.reproject = false;
    (void)plain.render(request);
  }
  EXPECT_EQ(bytes_differing(kept.out(), plain.out()), 0u);
  const std::vector<glm::vec4> a(kept.composite().begin(), kept.composite().end());
  const std::vector<glm::vec4> b(plain.composite().begin(), plain.composite().end());
  EXPECT_TRUE(a == b);
}

TEST(Reprojection, ANewHistoryTakesTheSamplesOfAtMostReprojectFramesFrames) {
  // Four held frames of one ray a pixel, all kept; then a focus change that
  // asks for k of them. Each frame more adds samples, and none adds more
  // than its own: the region's pixels.
  const Scene scene = ball_scene();
  std::uint64_t moved[4] = {};
  std::uint64_t held_pixels = 0;
  for (std::uint32_t k = 1; k <= 3; ++k) {
    Frames frames(scene);
    for (std::uint32_t n = 0; n < 4; ++n)
      held_pixels = frames.render(still_uniform(scene, 1, 70u + n)).traced_pixels;
    FrameRequest pull = still_uniform(scene, 1, 80u);
    pull.camera.focus_distance_m = 1.2f;
    pull.accumulation.reproject_frames = k;
    const FrameReport report = frames.render(pull);
    ASSERT_TRUE(report.history_restarted);
    moved[k] = report.reprojected_samples;
  }
  EXPECT_GT(moved[1], 0u);
  for (std::uint32_t k = 1; k <= 3; ++k) {
    EXPECT_LE(moved[k], k * held_pixels) << k << " frames";
    if (k > 1) {
      EXPECT_GT(moved[k], moved[k - 1]) << k << " frames";
    }
  }
}

// A history stops growing at max_samples (accumulation.h), the samples
// moved into it counted. After a pull of a new history a frame (0.1 D
// each), whose moved samples and first rays alike fill more than 8 samples
// a pixel, the still frames' shares by noise give out. (The cap took the
// samples so far from the pattern's room, unsigned: moved samples past it
// wrapped the difference, and the history grew to 23 samples a pixel,
// still tracing 76-99 rays a frame 40 frames on.)
TEST(Reprojection, MovedSamplesCountTowardsTheMostAHistoryTakes) {
  const Scene scene = ball_scene();
  Frames frames(scene);
  const auto at = [&](int step, std::uint32_t seed) {
    FrameRequest request = still(scene, 1, seed);
    request.accumulation.max_samples = 8;
    request.camera.focus_distance_m = 1.0f / (0.5f + 0.1f * float(step));
    return request;
  };
  std::uint64_t moved = 0;
  for (int k = 0; k < 12; ++k)
    moved += frames.render(at(k, 90u + std::uint32_t(k))).reprojected_samples;
  EXPECT_GT(moved, 0u);
  FrameReport report;
  std::uint32_t after_ten = 0;
  std::uint64_t rays_late = 0;
  for (int k = 0; k < 40; ++k) { // held where the pull ended
    report = frames.render(at(11, 200u + std::uint32_t(k)));
    if (k == 9)
      after_ten = report.history_samples;
    if (k >= 10)
      rays_late += report.camera_rays;
  }
  EXPECT_GE(after_ten, 8u) << "moved samples and the first rays fill the history";
  EXPECT_EQ(report.history_samples, after_ten) << "and it grows no more";
  // Only the few pixels that the moved samples left short of 8 take a ray
  // now and then (a share by noise rounded up at random).
  EXPECT_LT(rays_late, report.traced_pixels / 10) << "30 frames, a tenth of one frame's rays";
}

TEST(Reprojection, TheSamplesMovedAreTheSameOnAnyNumberOfThreads) {
  // Each thread moves the samples that land in its own band of rows, in the
  // order stored: one, two or seven threads give the same sums, bit for bit.
  const Scene scene = ball_scene();
  std::vector<std::vector<glm::vec4>> composites;
  for (const int threads : {1, 2, 7}) {
    Frames frames(scene, false, Executor::cpu, threads);
    std::uint64_t moved = 0;
    for (int k = 0; k < 6; ++k) {
      FrameRequest pull = still(scene, 1, 40u + std::uint32_t(k));
      pull.camera.focus_distance_m = 2.0f - 0.2f * float(k);
      moved += frames.render(pull).reprojected_samples;
    }
    EXPECT_GT(moved, 0u) << threads;
    composites.emplace_back(frames.composite().begin(), frames.composite().end());
  }
  EXPECT_TRUE(composites[0] == composites[1]);
  EXPECT_TRUE(composites[0] == composites[2]);
}

} // namespace
} // namespace camhead::renderer
