// A history's first frame shares its rays after the first
// (renderer/src/ray_shares.h, share_first_frame_rays), on its own: one
// sample a pixel of a frame with a vertical edge of the virtual objects
// down its middle, over a camera image of random texture. In focus the
// rays go to the edge; blurred by a pixel or more they go alike. And the
// reconstruction leaves the pixels that took more alone
// (defocus_filter.h, keep_above_samples). Then the same through the CPU
// reference's live frames (history_support.h): less error for the same rays
// in focus, the history within its most samples, a blurred frame alike.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <glm/vec4.hpp>

#include "camhead/renderer/gpu_layout.h"
#include "defocus_filter.h"
#include "history_support.h"
#include "pixel_span.h"
#include "ray_shares.h"
#include "worker_pool.h"

#include <gtest/gtest.h>

namespace camhead::renderer::cpu {
namespace {

constexpr std::uint32_t kWidth = 32;
constexpr std::uint32_t kHeight = 16;
constexpr std::uint32_t kEdge = 16; // the virtual part starts at this column
constexpr float kFocusM = 2.0f;

gpu::FrameParams camera() {
  gpu::FrameParams frame{};
  frame.cam_forward = {0.0f, 0.0f, -1.0f, 0.0f};
  // Aperture radius 40 mm, 100 px focal length: 4 px of blur radius a dioptre.
  frame.lens = {0.04f, kFocusM, 100.0f, 1.0f};
  frame.image = {kWidth, kHeight, 1u, 1u};
  return frame;
}

float luminance(const glm::vec4 &rgb) {
  return 0.2126f * rgb.x + 0.7152f * rgb.y + 0.0722f * rgb.z;
}

struct OneRayFrame {
  std::vector<PixelSpan> spans;
  std::vector<glm::vec4> aux, plate;
  std::vector<std::uint32_t> counts, own;
};

// Every pixel traced once, hitting a surface at `depth_m`; the camera image
// random in each pixel when `textured`; the samples' composite the camera's
// pixel, plus `step` right of the edge (the virtual objects).
OneRayFrame one_ray_frame(float depth_m, bool textured, float step) {
  OneRayFrame f;
  const std::size_t pixels = std::size_t(kWidth) * kHeight;
  f.aux.resize(pixels);
  f.plate.resize(pixels, glm::vec4(0.3f, 0.3f, 0.3f, 0.0f));
  f.counts.assign(pixels, 1u);
  f.own.assign(pixels, 1u);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> grey(0.05f, 0.95f);
  for (std::uint32_t y = 0; y < kHeight; ++y) {
    f.spans.push_back({y, 0, kWidth});
    for (std::uint32_t x = 0; x < kWidth; ++x) {
      const std::size_t i = std::size_t(y) * kWidth + x;
      if (textured)
        f.plate[i] = glm::vec4(grey(rng), grey(rng), grey(rng), 0.0f);
      const float composite = luminance(f.plate[i]) + (x >= kEdge ? step : 0.0f);
      f.aux[i] = glm::vec4(depth_m, 1.0f, composite, composite * composite);
    }
  }
  return f;
}

struct Shared {
  FirstFrameShared result;
  std::vector<std::uint32_t> shares;
};

Shared share(const OneRayFrame &f, std::uint32_t rpp) {
  const std::size_t pixels = f.aux.size();
  std::vector<float> sigma(pixels), noise(pixels);
  Shared out;
  out.shares.assign(pixels, 0u);
  FirstFrameShares settings;
  settings.rays_per_pixel = rpp;
  settings.most = 256;
  settings.pattern_room = 256;
  settings.rounding_key = 7;
  WorkerPool pool(2);
  out.result = share_first_frame_rays(f.spans, camera(), f.aux, f.plate, true, f.counts, f.own,
                                      settings, {sigma, noise, out.shares}, pool);
  return out;
}

std::uint64_t rays_in_columns(const Shared &s, std::uint32_t x0, std::uint32_t x1) {
  std::uint64_t rays = 0;
  for (std::uint32_t y = 0; y < kHeight; ++y)
    for (std::uint32_t x = x0; x < x1; ++x)
      rays += s.shares[std::size_t(y) * kWidth + x];
  return rays;
}

// The least and the most rays of the pixels `columns` from the edge or more.
std::pair<std::uint32_t, std::uint32_t> range_off_edge(const Shared &s, std::uint32_t columns) {
  std::uint32_t least = ~0u, most = 0;
  for (std::uint32_t y = 0; y < kHeight; ++y)
    for (std::uint32_t x = 0; x < kWidth; ++x)
      if (x + columns <= kEdge - 1 || x >= kEdge + columns) {
        least = std::min(least, s.shares[std::size_t(y) * kWidth + x]);
        most = std::max(most, s.shares[std::size_t(y) * kWidth + x]);
      }
  return {least, most};
}

TEST(FirstFrameShares, InFocusTheRaysGoToTheEdgeNotToTheCameraTexture) {
  constexpr std::uint32_t kRpp = 3;
  const std::uint64_t budget = std::uint64_t(kWidth) * kHeight * (kRpp - 1);
  std::uint64_t at_edge[2] = {};
  for (const bool textured : {false, true}) {
    const Shared s = share(one_ray_frame(kFocusM, textured, 0.5f), kRpp);
    EXPECT_TRUE(s.result.by_spread);
    // The columns either side of the edge see it in their 3x3
    // neighbourhood: each takes more than any pixel two columns off it, up
    // to 16 times the frame's rays.
    const std::uint32_t most_off_edge = range_off_edge(s, 2).second;
    for (std::uint32_t y = 0; y < kHeight; ++y)
      for (std::uint32_t x = kEdge - 1; x <= kEdge; ++x) {
        const std::uint32_t n = s.shares[std::size_t(y) * kWidth + x];
        EXPECT_GT(n, 4 * most_off_edge) << x << "," << y;
        EXPECT_LE(n, 16 * kRpp);
      }
    at_edge[textured] = rays_in_columns(s, kEdge - 1, kEdge + 1);
    EXPECT_NEAR(double(s.result.rays), double(budget), 0.05 * double(budget));
    std::uint64_t sum = 0;
    for (const std::uint32_t n : s.shares)
      sum += n;
    EXPECT_EQ(sum, s.result.rays);
  }
  // The camera's texture changes next to nothing.
  EXPECT_NEAR(double(at_edge[1]), double(at_edge[0]), 0.02 * double(at_edge[0]));
}

TEST(FirstFrameShares, WithNothingVirtualTheCameraTextureDrawsNoRays) {
  // No edge: every pixel's want is the floor, so each takes the frame's rays.
  const Shared s = share(one_ray_frame(kFocusM, true, 0.0f), 3);
  for (const std::uint32_t n : s.shares)
    EXPECT_NEAR(double(n), 2.0, 1.0);
  EXPECT_NEAR(double(s.result.rays), 2.0 * kWidth * kHeight, 0.02 * 2.0 * kWidth * kHeight);
}

TEST(FirstFrameShares, BlurredByAPixelOrMoreEveryPixelTakesTheRaysAlike) {
  // Against a focus of 2 m (0.5 D), at 4 px a dioptre: 1 m blurs by 2 px,
  // 8 m by 1.5 px (behind the focus).
  for (const float depth : {1.0f, 8.0f}) {
    const Shared s = share(one_ray_frame(depth, true, 0.5f), 4);
    EXPECT_FALSE(s.result.by_spread) << depth;
    for (const std::uint32_t n : s.shares)
      ASSERT_EQ(n, 3u) << depth;
  }
  // 1.8 m: 0.22 px, sharp.
  const Shared sharp = share(one_ray_frame(1.8f, true, 0.5f), 4);
  EXPECT_TRUE(sharp.result.by_spread);
  EXPECT_GT(double(rays_in_columns(sharp, kEdge - 1, kEdge + 1)), 0.5 * double(sharp.result.rays));
}

TEST(FirstFrameShares, TheReconstructionLeavesThePixelsThatTookMoreAlone) {
  // A row of pixels blurred by 2 px, one holding 16 samples of another
  // colour among neighbours of 2: kept above 4 samples, it keeps its own mean
  // and lends its neighbours nothing; not kept, it pulls them towards it.
  const OneRayFrame f = one_ray_frame(1.0f, false, 0.0f);
  const std::size_t pixels = f.aux.size();
  std::vector<glm::vec4> mixed(pixels), real(pixels, glm::vec4(0.2f, 0.2f, 0.2f, 0.0f) * 2.0f);
  std::vector<glm::vec4> aux = f.aux;
  std::vector<std::uint32_t> counts(pixels, 2u);
  const std::size_t edge = std::size_t(kHeight / 2) * kWidth + kEdge;
  for (std::size_t i = 0; i < pixels; ++i) {
    aux[i] *= 2.0f; // two samples' sums
    mixed[i] = glm::vec4(0.2f, 0.2f, 0.2f, 0.0f) * 2.0f;
  }
  counts[edge] = 16;
  aux[edge] = f.aux[edge] * 16.0f;
  mixed[edge] = glm::vec4(1.0f, 1.0f, 1.0f, 1.0f) * 16.0f;
  real[edge] = glm::vec4(0.2f, 0.2f, 0.2f, 0.0f) * 16.0f;
  std::vector<glm::vec4> out_mixed(pixels), out_real(pixels), scratch_mixed(pixels),
      scratch_real(pixels);
  std::vector<float> scratch_weight(pixels), blur(pixels);
  std::vector<DefocusGaussian> gaussian(pixels);
  WorkerPool pool(2);
  const auto filtered = [&](std::uint32_t keep_above) {
    DefocusFilterSettings settings;
    settings.keep_above_samples = keep_above;
    filter_defocus(
        camera(), f.spans, mixed, real, aux, counts, settings,
        {out_mixed, out_real, scratch_mixed, scratch_real, scratch_weight, blur, gaussian}, pool);
    return std::pair(out_mixed[edge], out_mixed[edge - 1]);
  };
  const auto [kept_edge, kept_neighbour] = filtered(4);
  EXPECT_EQ(kept_edge, glm::vec4(1.0f));
  EXPECT_NEAR(kept_neighbour.x, 0.2f, 1e-6f);
  EXPECT_EQ(kept_neighbour.w, 0.0f);
  const auto [edge_mean, neighbour_mean] = filtered(std::numeric_limits<std::uint32_t>::max());
  EXPECT_LT(edge_mean.x, 0.99f);
  EXPECT_GT(neighbour_mean.x, 0.3f);
}

} // namespace
} // namespace camhead::renderer::cpu

namespace camhead::renderer {
namespace {

using namespace history;

// The root mean square of the errors of eight first frames of `rpp` rays,
// each pixel alike and shared by noise, reconstructed or not.
std::pair<double, double> first_frame_errors(const Scene &scene, const Frames &reference,
                                             std::uint32_t rpp, bool reconstruct) {
  double alike = 0.0, by_spread = 0.0;
  std::uint64_t rays_alike = 0, rays_by_spread = 0;
  for (std::uint32_t n = 0; n < 8; ++n) {
    Frames a(scene), b(scene);
    FrameRequest uniform = still_uniform(scene, rpp, 900 + n), shared = still(scene, rpp, 900 + n);
    uniform.accumulation.reconstruct = shared.accumulation.reconstruct = reconstruct;
    rays_alike += a.render(uniform).camera_rays;
    rays_by_spread += b.render(shared).camera_rays;
    alike += std::pow(virtual_error(a, reference), 2);
    by_spread += std::pow(virtual_error(b, reference), 2);
  }
  // The budget holds: the shares round at random, so within a few percent.
  EXPECT_NEAR(double(rays_by_spread), double(rays_alike), 0.03 * double(rays_alike));
  return {std::sqrt(alike / 8.0), std::sqrt(by_spread / 8.0)};
}

TEST(FrameHistory, AFirstFrameInFocusGivesItsRaysToTheEdges) {
  // At 64x48 the ball scene is sharp (blur radii under half a pixel), so a
  // first frame, after a ray in every pixel, gives the rest by the spread of
  // its neighbours' rays: to the ball's rim and the shadows'. Against the
  // same rays alike: alone (4 rpp), and with the reconstruction (8 rpp;
  // at 2 and 4 rpp this small scene's nearly sharp surfaces gain as much
  // from the reconstruction of rays alike, as the locked-off rig's do).
  const Scene scene = ball_scene();
  const Frames reference = converged(scene, 77);
  const auto [alike4, spread4] = first_frame_errors(scene, reference, 4, false);
  const auto [alike8, spread8] = first_frame_errors(scene, reference, 8, true);
  std::printf("[ history ] first frames in focus: error %.4f alike, %.4f by spread at 4 rpp; "
              "%.4f and %.4f reconstructed at 8 rpp\n",
              alike4, spread4, alike8, spread8);
  EXPECT_LT(spread4, 0.9 * alike4);
  EXPECT_LT(spread8, 0.9 * alike8);
}

TEST(FrameHistory, AFirstFrameSharedKeepsTheHistoryWithinItsMostSamples) {
  // A first frame's edges, which took many rays, and a first frame whose
  // rays all went alike (every pixel blurred) both stop at the most samples
  // a pixel, whatever the frames after them give alike: in all, no more
  // rays than the region's pixels times the most.
  struct Case {
    Scene scene;
    std::uint32_t rpp, most;
  };
  for (const Case &c : {Case{ball_scene(), 3, 4}, Case{defocused_ball_scene(), 5, 8}}) {
    Frames frames(c.scene);
    FrameRequest request = still(c.scene, c.rpp, 31);
    request.accumulation.max_samples = c.most;
    std::uint64_t rays = 0, pixels = 0;
    FrameReport report;
    for (int n = 0; n < 12; ++n) {
      report = frames.render(request);
      rays += report.camera_rays;
      pixels = report.traced_pixels;
    }
    EXPECT_EQ(report.camera_rays, 0u) << c.rpp;
    EXPECT_LE(rays, pixels * c.most) << c.rpp;
    EXPECT_LE(report.history_samples, c.most) << c.rpp;
  }
}

TEST(FrameHistory, AFirstFrameBlurredEverywhereTracesItsRaysAlike) {
  // Focused at 0.3 m, every pixel is blurred by 5 to 7: the reconstruction
  // smooths them all, and a first frame shared by noise is the frame alike.
  const Scene scene = defocused_ball_scene();
  Frames alike(scene), by_noise(scene);
  const FrameReport a = alike.render(still_uniform(scene, 4, 41));
  const FrameReport b = by_noise.render(still(scene, 4, 41));
  EXPECT_EQ(a.camera_rays, b.camera_rays);
  EXPECT_EQ(bytes_differing(alike.out(), by_noise.out()), 0u);
}

} // namespace
} // namespace camhead::renderer
