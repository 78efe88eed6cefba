// One sample for the pixels that no ray can take into the scene
// (TRACING_SKIP_EMPTY_PIXELS, kernel.glsl's pixel_misses_scene): the same
// image as tracing every sample, also at the rims of strongly defocused
// objects, whose blur reaches pixels the pinhole rays would call empty.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/scene_loader.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

// ar_basic without its ground: small virtual objects and a small real box
// over the plate, at f/1.4 focused at 6 m so that the near box (0.6 m) is
// blurred over tens of pixels.
renderer::Scene sparse_scene() {
  renderer::Scene scene =
      test::downscaled(renderer::load_scene(test::reference_dir() / "ar_basic.json"), 4);
  std::erase_if(scene.objects, [](const renderer::Object &o) { return o.name == "ground"; });
  scene.camera.f_number = 1.4f;
  scene.camera.focus_distance_m = 6.0f;
  return scene;
}

double largest_difference(const renderer::Image &a, const renderer::Image &b) {
  double largest = 0.0;
  for (std::size_t i = 0; i < a.data.size(); ++i)
    largest = std::max(largest, double(std::abs(a.data[i] - b.data[i])));
  return largest;
}

// Through the ideal lens, and through lens models (kernel.glsl bounds a
// pixel's bundle by the preimage of its centre and the lens's least
// stretch there): a strong barrel with its principal point off centre, and
// a pincushion with non-square pixels.
TEST(EmptyPixels, OneSampleStandsForAllWithoutChangingTheImage) {
  CAMHEAD_REQUIRE_VULKAN();
  const renderer::Scene scene = sparse_scene();
  const renderer::CompiledScene compiled = renderer::compile_scene(scene);
  renderer::GpuTracer tracer;
  tracer.load(compiled);
  renderer::LensModel barrel, pincushion;
  barrel.k1 = -0.3f;
  barrel.k2 = 0.08f;
  barrel.principal_point = {0.54f, 0.47f};
  pincushion.k1 = 0.25f;
  pincushion.fy_over_fx = 0.97f;
  for (const renderer::LensModel &lens : {renderer::LensModel{}, barrel, pincushion}) {
    renderer::FrameCamera camera = renderer::scene_camera(scene);
    camera.lens_model = lens;
    renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, camera, 16);
    const renderer::RenderResult traced = tracer.render(frame);
    frame.tracing.w |= TRACING_SKIP_EMPTY_PIXELS;
    const renderer::RenderResult skipped = tracer.render(frame);
    ASSERT_TRUE(test::all_finite(skipped.composite));
    // Every sample of a skipped pixel is the same world colour and plate, so
    // only the rounding of 16 additions against one multiplication differs;
    // a pixel skipped wrongly would lose the blurred rim (differences of the
    // order of the plate's contrast, 0.1 and more).
    const double composite = largest_difference(traced.composite, skipped.composite);
    const double mask = largest_difference(traced.mask, skipped.mask);
    std::printf("k1 %.2f: largest difference with and without skipping: composite %.2e, mask "
                "%.2e\n",
                lens.k1, composite, mask);
    EXPECT_LT(composite, 1e-5) << lens.k1;
    EXPECT_LT(mask, 1e-6) << lens.k1;
  }
}

} // namespace
} // namespace camhead
