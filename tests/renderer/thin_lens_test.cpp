// The thin-lens camera against its formula (method.md section 1): the blur of
// a defocused edge has the diameter the thin-lens equation predicts, and
// stratified sampling converges faster than independent random sampling.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

struct LensCase {
  float f_number;
  float focus_m;
  float depth_m;
};

class BlurCircle : public ::testing::TestWithParam<LensCase> {};

TEST_P(BlurCircle, DiameterMatchesThinLensFormula) {
  CAMHEAD_REQUIRE_VULKAN();
  const LensCase c = GetParam();
  const renderer::Scene scene = test::edge_scene(c.f_number, c.focus_m, c.depth_m);
  const renderer::RenderResult result = test::render_gpu(scene, 256);
  ASSERT_TRUE(test::all_finite(result.composite));
  const double expected = test::coc_px(scene, c.depth_m);
  const double measured = test::measured_blur_diameter(test::row_average(result.composite));
  std::printf("f/%.1f focus %.2f m, edge at %.2f m: CoC formula %.3f px, measured %.3f px\n",
              c.f_number, c.focus_m, c.depth_m, expected, measured);
  EXPECT_NEAR(measured, expected, 0.25);
}

INSTANTIATE_TEST_SUITE_P(Depths, BlurCircle,
                         ::testing::Values(LensCase{2.0f, 1.0f, 1.0f},   // in focus: 0 px
                                           LensCase{2.0f, 1.0f, 0.5f},   // near: 8.9 px
                                           LensCase{2.0f, 1.0f, 2.0f},   // far: 4.4 px
                                           LensCase{2.0f, 1.0f, 100.0f}, // near infinity
                                           LensCase{4.0f, 1.0f, 3.0f},   // 3.0 px
                                           LensCase{1.4f, 2.0f, 1.0f},   // 6.4 px
                                           LensCase{8.0f, 0.5f, 4.0f},   // 3.9 px
                                           LensCase{16.0f, 1.0f, 0.3f}   // 2.6 px
                                           ),
                         [](const ::testing::TestParamInfo<LensCase> &param_info) {
                           // e.g. f2_0_focus1_00m_edge0_50m
                           char name[64];
                           std::snprintf(name, sizeof name, "f%.1f_focus%.2fm_edge%.2fm",
                                         param_info.param.f_number, param_info.param.focus_m,
                                         param_info.param.depth_m);
                           std::string s = name;
                           std::replace(s.begin(), s.end(), '.', '_');
                           return s;
                         });

// method.md section 2: stratified jittered sampling of pixel and aperture.
// On a defocused edge its error falls faster than the N^-1/2 of independent
// samples (jittered sampling of a discontinuity: about N^-3/4).
TEST(Stratification, EdgeErrorFallsFasterThanInverseSquareRoot) {
  CAMHEAD_REQUIRE_VULKAN();
  renderer::Scene scene = test::edge_scene(2.0f, 1.0f, 0.5f, 128, 16);
  scene.render.seed = 7;
  const renderer::Image reference = test::render_gpu(scene, 8192).composite;
  scene.render.seed = 1;
  std::vector<double> rpps, errors;
  for (int n : {4, 16, 64, 256}) {
    const double err = test::rmse(reference, test::render_gpu(scene, n).composite);
    std::printf("%4d rpp: RMSE %.6f\n", n, err);
    rpps.push_back(n);
    errors.push_back(err);
  }
  const double slope = test::log_log_slope(rpps, errors);
  std::printf("error ~ N^%.3f between 4 and 256 rpp (independent sampling: N^-0.5)\n", slope);
  EXPECT_LT(slope, -0.5);
}

// f-number 0 is the pinhole: an edge at any depth stays sharp.
TEST(ThinLens, PinholeKeepsEveryDepthSharp) {
  CAMHEAD_REQUIRE_VULKAN();
  for (float depth : {0.3f, 1.0f, 50.0f}) {
    const renderer::Scene scene = test::edge_scene(0.0f, 1.0f, depth);
    const double measured =
        test::measured_blur_diameter(test::row_average(test::render_gpu(scene, 64).composite));
    EXPECT_NEAR(measured, 0.0, 0.25) << "edge at " << depth << " m";
  }
}

} // namespace
} // namespace camhead
