// camhead against Blender Cycles (tests/assets/reference): at 1024 rays per
// pixel every layer of the reference scenes matches the Cycles render to a
// relative RMSE of 1 % or better. The Cycles images are independent ground
// truth: another renderer, another sampler, the same scene description.
#include <cstdio>
#include <string>

#include "camhead/renderer/image_io.h"
#include "camhead/renderer/scene_loader.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

constexpr int reference_rpp = 1024;
constexpr double tolerance = 0.01;

std::filesystem::path reference(const std::string &name) {
  return test::reference_dir() / name;
}

// compare.py's relRMSE on the red channel of `image`, for the mask layer,
// which Cycles stores as grey RGB.
double mask_relative_rmse(const renderer::Image &cycles_rgb, const renderer::Image &mask) {
  renderer::Image cycles_mask(mask.width, mask.height, 1);
  for (std::size_t i = 0; i < mask.pixel_count(); ++i) {
    cycles_mask.data[i] = cycles_rgb.data[i * 3];
  }
  return test::relative_rmse(cycles_mask, mask);
}

void report(const char *what, double rel) {
  std::printf("%-22s rel. RMSE vs Cycles %.4f (limit %.2f)\n", what, rel, tolerance);
}

TEST(CyclesReference, BoxesMatchAt1024Rpp) {
  const renderer::Scene scene = renderer::load_scene(reference("boxes.json"));
  const renderer::RenderResult r = test::render_fastest(scene, reference_rpp);
  ASSERT_TRUE(test::all_finite(r.mixed));
  const double rel =
      test::relative_rmse(renderer::read_image(reference("boxes_1024.exr")), r.mixed);
  report("boxes", rel);
  EXPECT_LE(rel, tolerance);
}

TEST(CyclesReference, ArBasicLayersAndCompositeMatchAt1024Rpp) {
  const renderer::Scene scene = renderer::load_scene(reference("ar_basic.json"));
  const renderer::RenderResult r = test::render_fastest(scene, reference_rpp);
  for (const auto *layer : {&r.composite, &r.mixed, &r.real, &r.mask}) {
    ASSERT_TRUE(test::all_finite(*layer));
  }
  const double mixed =
      test::relative_rmse(renderer::read_image(reference("ar_basic_mixed.exr")), r.mixed);
  const double real =
      test::relative_rmse(renderer::read_image(reference("ar_basic_real.exr")), r.real);
  const double mask =
      mask_relative_rmse(renderer::read_image(reference("ar_basic_mask.exr")), r.mask);
  const double composite =
      test::relative_rmse(renderer::read_image(reference("ar_basic_composite.exr")), r.composite);
  report("ar_basic mixed", mixed);
  report("ar_basic real", real);
  report("ar_basic mask", mask);
  report("ar_basic composite", composite);
  EXPECT_LE(mixed, tolerance);
  EXPECT_LE(real, tolerance);
  EXPECT_LE(mask, tolerance);
  EXPECT_LE(composite, tolerance);
}

} // namespace
} // namespace camhead
