// The image-space depth-of-field baseline (dof_gather.comp): an in-focus
// plane stays sharp, a point spreads over the circle of confusion of
// method.md section 1, and the depth-aware weights keep a sharp foreground's
// silhouette while a blurred foreground spreads over what lies behind it.
#include <cmath>
#include <cstdio>
#include <random>

#include "camhead/renderer/dof_gather.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::DofGather;
using renderer::RenderResult;

constexpr int kWidth = 64;
constexpr int kHeight = 40;
constexpr float kFocus = 1.0f; // m

// Aperture radius 1 cm, 500 px focal length: blur radius 5 |z - 1| / z px.
renderer::gpu::FrameParams lens() {
  renderer::gpu::FrameParams frame{};
  frame.lens = renderer::gpu::vec4(0.01f, kFocus, 500.0f, 1.0f);
  return frame;
}

// Pinhole layers of constant grey `value`, depth `depth`, no virtual object.
RenderResult layers(float value, float depth, int width = kWidth, int height = kHeight) {
  RenderResult r;
  r.mixed = renderer::Image(width, height, 3);
  r.real = renderer::Image(width, height, 3);
  r.mask = renderer::Image(width, height, 1);
  r.depth = renderer::Image(width, height, 1);
  for (float &v : r.mixed.data)
    v = value;
  r.real.data = r.mixed.data;
  for (float &z : r.depth.data)
    z = depth;
  return r;
}

void set_pixel(RenderResult &r, int x, int y, float value, float depth) {
  for (int c = 0; c < 3; ++c) {
    r.mixed.at(x, y)[c] = value;
    r.real.at(x, y)[c] = value;
  }
  r.depth.at(x, y)[0] = depth;
}

TEST(DofGather, CocRadiusIsHalfTheThinLensBlurCircle) {
  // c = 2R p |z - d_f| / (z d_f) = 2 * 0.01 * 500 * 3 / 4 = 7.5 px at z = 4.
  EXPECT_FLOAT_EQ(renderer::coc_radius_px(lens(), 4.0f), 3.75f);
  EXPECT_FLOAT_EQ(renderer::coc_radius_px(lens(), kFocus), 0.0f);
  EXPECT_NEAR(renderer::coc_radius_px(lens(), 0.0f), 5.0f, 1e-5f); // nothing hit: infinity
}

TEST(DofGather, InFocusPlaneStaysSharp) {
  CAMHEAD_REQUIRE_VULKAN();
  RenderResult in = layers(0.0f, kFocus);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (float &v : in.mixed.data)
    v = u(rng);
  in.real.data = in.mixed.data;
  DofGather gather;
  const renderer::DofGatherResult out = gather.apply(in, lens(), {}, {.max_radius_px = 8.0f});
  for (std::size_t i = 0; i < in.mixed.data.size(); ++i)
    ASSERT_NEAR(out.image.composite.data[i], in.mixed.data[i], 1e-5f) << "at " << i / 3;
}

// A single bright pixel on a black plane at the same depth spreads over a
// disk of the circle of confusion's radius and keeps its energy.
TEST(DofGather, PointSpreadsOverTheCircleOfConfusion) {
  CAMHEAD_REQUIRE_VULKAN();
  DofGather gather;
  for (const float depth : {4.0f, 0.4f}) { // behind and in front of the focal plane
    const float radius = renderer::coc_radius_px(lens(), depth);
    RenderResult in = layers(0.0f, depth);
    set_pixel(in, kWidth / 2, kHeight / 2, 1.0f, depth);
    const renderer::DofGatherResult out = gather.apply(in, lens(), {}, {.max_radius_px = 12.0f});
    double energy = 0.0, extent = 0.0;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        const float v = out.image.composite.at(x, y)[0];
        energy += v;
        if (v > 1e-6f)
          extent = std::max(extent, std::hypot(x - kWidth / 2.0, y - kHeight / 2.0));
      }
    EXPECT_NEAR(extent, radius, 0.75) << "depth " << depth;
    EXPECT_NEAR(energy, 1.0, 0.1) << "depth " << depth;
  }
}

// Left half: in-focus white foreground; right half: defocused black
// background (radius 5 px). Neither bleeds into the other.
TEST(DofGather, SharpForegroundDoesNotBleed) {
  CAMHEAD_REQUIRE_VULKAN();
  RenderResult in = layers(0.0f, 0.0f); // background: nothing hit, infinitely far
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth / 2; ++x)
      set_pixel(in, x, y, 1.0f, kFocus);
  DofGather gather;
  const renderer::DofGatherResult out = gather.apply(in, lens());
  EXPECT_NEAR(out.max_radius_px, 5.0, 1e-3);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth / 2; ++x)
      ASSERT_NEAR(out.image.composite.at(x, y)[0], 1.0f, 1e-5f) << x << "," << y;
    for (int x = kWidth / 2; x < kWidth; ++x)
      ASSERT_NEAR(out.image.composite.at(x, y)[0], 0.0f, 1e-5f) << x << "," << y;
  }
}

// Left half: a white foreground at 0.4 m (radius 7.5 px) before an in-focus
// black background: its blur reaches over the background by about its
// radius, fading outwards, while its inside stays white.
TEST(DofGather, BlurredForegroundSpreadsOverBackground) {
  CAMHEAD_REQUIRE_VULKAN();
  RenderResult in = layers(0.0f, kFocus);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth / 2; ++x)
      set_pixel(in, x, y, 1.0f, 0.4f);
  DofGather gather;
  const renderer::DofGatherResult out = gather.apply(in, lens());
  const int y = kHeight / 2;
  const auto at = [&](int x) { return out.image.composite.at(x, y)[0]; };
  const int edge = kWidth / 2; // first background column
  EXPECT_NEAR(at(edge - 12), 1.0f, 1e-4f);
  EXPECT_GT(at(edge), 0.3f);
  EXPECT_GT(at(edge), at(edge + 3));
  EXPECT_GT(at(edge + 3), at(edge + 6));
  EXPECT_GT(at(edge + 6), 0.0f);
  EXPECT_NEAR(at(edge + 9), 0.0f, 1e-6f);
}

// With a camera plate, the blurred mask of a virtual object composites as
// method.md equation 4: I_c where nothing virtual is near, I_m inside it.
TEST(DofGather, CompositesBlurredLayersWithThePlate) {
  CAMHEAD_REQUIRE_VULKAN();
  RenderResult in = layers(0.25f, kFocus);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth / 2; ++x) {
      set_pixel(in, x, y, 0.0f, 0.4f);
      for (int c = 0; c < 3; ++c)
        in.mixed.at(x, y)[c] = 1.0f; // virtual white; the real scene behind reads 0
      in.mask.at(x, y)[0] = 1.0f;
    }
  std::vector<glm::vec4> plate(std::size_t(kWidth) * kHeight, glm::vec4(0.5f, 0.5f, 0.5f, 0.0f));
  DofGather gather;
  const renderer::DofGatherResult out = gather.apply(in, lens(), plate);
  const int y = kHeight / 2;
  EXPECT_NEAR(out.image.composite.at(2, y)[0], 1.0f, 1e-4f);
  EXPECT_NEAR(out.image.composite.at(kWidth - 2, y)[0], 0.5f, 1e-5f);
  const float m = out.image.mask.at(kWidth / 2, y)[0];
  EXPECT_GT(m, 0.2f);
  EXPECT_LT(m, 0.8f);
}

// A device may stop a shader's loops after so many iterations (lavapipe:
// 65535 of all of them together, vulkan_context.h); a gather whose window
// needs more would take part of it, silently, and the blur would lose its
// symmetry. A 4x200 strip at one depth, blurred far wider than itself, with
// one bright pixel at one end: the pixel at the other end must see exactly
// what the bright one sees of it from the other end. (lavapipe, before the
// reach was bounded: the bottom pixel saw the top one, not the reverse.)
TEST(DofGather, ALongWindowIsGatheredWholeOrNotAtAll) {
  constexpr int w = 4, h = 200;
  renderer::gpu::FrameParams wide{};
  wide.lens = renderer::gpu::vec4(1.0f, kFocus, 500.0f, 1.0f); // 500 px of blur at 0.5 m
  const auto strip = [&](int bright_y) {
    RenderResult r = layers(0.0f, 0.5f, w, h);
    set_pixel(r, 1, bright_y, 1.0f, 0.5f);
    return r;
  };
  DofGather gather;
  const renderer::DofGatherResult bottom_lit =
      gather.apply(strip(h - 1), wide, {}, {.max_radius_px = 200.0f});
  const renderer::DofGatherResult top_lit =
      gather.apply(strip(0), wide, {}, {.max_radius_px = 200.0f});
  EXPECT_EQ(bottom_lit.max_radius_px, top_lit.max_radius_px);
  const float top_sees = bottom_lit.image.mixed.at(1, 0)[0];
  const float bottom_sees = top_lit.image.mixed.at(1, h - 1)[0];
  std::printf("reach %.0f px: the top pixel sees %.3g of the bottom one, the bottom %.3g of the "
              "top\n",
              bottom_lit.max_radius_px, top_sees, bottom_sees);
  EXPECT_FLOAT_EQ(top_sees, bottom_sees);
}

} // namespace
} // namespace camhead
