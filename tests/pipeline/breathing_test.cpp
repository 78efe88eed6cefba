// Focus breathing in the picture (issue 25, test 5): through a focus pull
// the rendered image scale follows the profile's projection focal length.
// Two small squares facing the camera, rendered through the lens state the
// example 35 mm profile gives at each focus of a pull (lens_camera, as
// `camhead run` makes the frame's camera); their distance apart in the
// picture, measured by their coverage's centroids, scales with the
// projection focal length (38.9 mm at 0.3 m to 35.0 mm at infinity).
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "camhead/lens_control/lens_profile.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "run/lens_camera.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 320, kHeight = 180;

renderer::Object square(glm::vec3 centre) {
  renderer::Object o;
  o.type = renderer::ShapeType::plane;
  o.center = centre;
  o.rotation_deg = {90.0f, 0.0f, 0.0f}; // facing the camera
  o.size = glm::vec3(0.05f, 1.0f, 0.05f);
  return o;
}

// The centroid of the coverage in a window around `near`.
glm::dvec2 centroid(const renderer::Image &mask, glm::dvec2 near) {
  double sum = 0.0;
  glm::dvec2 at(0.0);
  for (int y = int(near.y) - 12; y <= int(near.y) + 12; ++y)
    for (int x = int(near.x) - 12; x <= int(near.x) + 12; ++x) {
      if (x < 0 || y < 0 || x >= kWidth || y >= kHeight)
        continue;
      const double m = mask.data[std::size_t(y) * kWidth + std::size_t(x)];
      sum += m;
      at += m * glm::dvec2(x + 0.5, y + 0.5);
    }
  return at / sum;
}

TEST(Breathing, ThePicturesScaleFollowsTheProjectionFocalLengthThroughAPull) {
  const lens_control::LensProfile profile = lens_control::LensProfile::load(
      fs::path(CAMHEAD_SOURCE_DIR) / "scenes/lenses/example_35mm.json");
  renderer::Scene scene;
  scene.render.width = kWidth;
  scene.render.height = kHeight;
  scene.camera.sensor_width_mm = 36.0f;
  scene.materials.push_back({"grey", renderer::MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}});
  // 1.2 m apart across the view at 3 m: about 90 px at 35 mm.
  scene.objects = {square({-0.6f, 0.1f, -3.0f}), square({0.6f, -0.1f, -3.0f})};
  const renderer::CompiledScene compiled = renderer::compile_scene(scene);

  double reference_apart = 0.0, reference_mm = 0.0;
  for (const double counts : {16383.0, 11800.0, 6900.0, 2100.0, 0.0}) { // infinity to 0.3 m
    lens_control::LensCounts lens;
    lens.focus = lens_control::AxisReading{counts, 0, true};
    lens.iris = lens_control::AxisReading{0.0, 0, true};
    const lens_control::LensState state = profile.evaluate(lens);
    renderer::FrameCamera camera = lens_camera(renderer::scene_camera(scene), state);
    camera.f_number = 0.0f; // sharp: the squares' edges measure the scale alone
    const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, camera, 64);
    const renderer::RenderResult result = renderer::render_cpu(compiled, frame);
    const double f_px = frame.lens.z;
    const glm::dvec2 a =
        centroid(result.mask, {kWidth / 2.0 - 0.6 / 3.0 * f_px, kHeight / 2.0 - 0.1 / 3.0 * f_px});
    const glm::dvec2 b =
        centroid(result.mask, {kWidth / 2.0 + 0.6 / 3.0 * f_px, kHeight / 2.0 + 0.1 / 3.0 * f_px});
    const double apart = glm::length(b - a);
    const double mm = state.projection_focal_length_mm.value;
    if (reference_apart == 0.0) {
      reference_apart = apart;
      reference_mm = mm;
    }
    std::printf("focus %.2f m: projection focal length %.3f mm, squares %.3f px apart (scale "
                "%.5f, focal length ratio %.5f)\n",
                state.focus_distance_m.value, mm, apart, apart / reference_apart,
                mm / reference_mm);
    // Each centroid lands within 0.02 px of the squares' projected centres
    // (the box-filtered coverage's sampling): 3e-4 of their distance.
    EXPECT_NEAR(apart / reference_apart, mm / reference_mm, 1e-3) << counts;
  }
  // The pull breathes by 11 %: a scale held fixed would fail above.
  EXPECT_GT(profile.projection_focal_length_mm(0, 0).value / reference_mm, 1.1);
}

} // namespace
} // namespace camhead::pipeline
