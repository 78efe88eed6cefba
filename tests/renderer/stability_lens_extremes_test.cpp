// Stability at extreme lens states (issue 4): f/0.95 to f/22, focus at the
// near limit and at infinity, focus nearer than the focal length, and the
// pinhole. The blur of an edge keeps the thin-lens diameter
// (scene-format.md: CoC_px = f_px (f / N) |1/d_f - 1/d|) at every extreme,
// N = 0 is the pinhole bit for bit, and no lens state puts a NaN or an
// infinity into an image.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/scene_loader.h"
#include "stability_support.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::RenderResult;
using renderer::Scene;

constexpr float kInfinity = std::numeric_limits<float>::infinity();

bool bit_identical(const RenderResult &a, const RenderResult &b) {
  return a.composite.data == b.composite.data && a.mixed.data == b.mixed.data &&
         a.real.data == b.real.data && a.mask.data == b.mask.data && a.depth.data == b.depth.data;
}

struct LensCase {
  const char *what;
  float f_number;
  float focus_m; // +inf: focused at infinity
  float depth_m; // of the edge
};

// The CoC formula with 1/d_f = 0 at infinity (test::coc_px divides).
double expected_coc(const Scene &scene, float depth_m) {
  return 2.0 * stability::blur_radius_px(scene, depth_m);
}

void check_blur(const std::vector<LensCase> &cases, bool gpu) {
  for (const LensCase &c : cases) {
    const Scene scene = test::edge_scene(c.f_number, c.focus_m, c.depth_m, 256, 4);
    const RenderResult r = gpu ? test::render_gpu(scene, 256) : test::render_cpu(scene, 256);
    ASSERT_TRUE(test::all_layers_finite(r)) << c.what;
    const double expected = expected_coc(scene, c.depth_m);
    const double measured = test::measured_blur_diameter(test::row_average(r.composite));
    const double tolerance = std::max(0.25, 0.02 * expected);
    std::printf("%-26s f/%-5.2f focus %8.3f m, edge %6.3f m: CoC formula %7.3f px, measured "
                "%7.3f px (%s)\n",
                c.what, c.f_number, c.focus_m, c.depth_m, expected, measured, gpu ? "GPU" : "CPU");
    EXPECT_NEAR(measured, expected, tolerance) << c.what;
  }
}

// ---------------------------------------------------------------- blur circle

TEST(LensExtremes, BlurCircleFromF095ToF22) {
  check_blur({{"widest aperture", 0.95f, 1.0f, 2.0f},
              {"widest aperture, near", 0.95f, 1.0f, 0.7f},
              {"fast", 1.4f, 3.0f, 1.0f},
              {"medium", 5.6f, 1.0f, 0.5f},
              {"slow", 11.0f, 1.0f, 0.3f},
              {"narrowest aperture", 22.0f, 1.0f, 0.3f},
              {"narrowest, close", 22.0f, 0.5f, 0.15f}},
             false);
}

TEST(LensExtremes, BlurCircleWithFocusAtTheNearLimit) {
  check_blur({{"near limit, in focus", 2.0f, 0.1f, 0.1f},
              {"near limit, behind", 2.0f, 0.2f, 0.3f},
              {"near limit f/0.95", 0.95f, 0.1f, 0.12f},
              {"near limit, far edge", 8.0f, 0.15f, 1.0f}},
             false);
}

// lens_control reports a lens focused at infinity as +inf metres
// (lens_state.h); the scene loader's largest focus is 1e6 m.
TEST(LensExtremes, BlurCircleWithFocusAtInfinity) {
  check_blur({{"infinity, far edge", 2.0f, kInfinity, 5.0f},
              {"infinity, mid edge", 2.0f, kInfinity, 2.0f},
              {"infinity f/0.95", 0.95f, kInfinity, 1.0f},
              {"1e6 m (loader maximum)", 2.0f, 1e6f, 2.0f}},
             false);
}

// The projection is Cycles' (scene-format.md): magnification from the focal
// length whatever the focus, so a focal plane nearer than the focal length
// is a plain plane, not the singularity of 1/f = 1/d_f + 1/v. The scene
// loader accepts it exactly as the reference does, and the blur follows the
// formula there too.
TEST(LensExtremes, FocusNearerThanTheFocalLengthFollowsTheFormula) {
  check_blur({{"focus 30 mm < f = 50 mm", 22.0f, 0.03f, 0.04f},
              {"focus 20 mm, in focus", 16.0f, 0.02f, 0.02f},
              {"focus 10 mm, edge at 1 m", 22.0f, 0.01f, 1.0f}},
             false);
}

TEST(LensExtremes, BlurCircleAtTheExtremesOnGpu) {
  CAMHEAD_REQUIRE_VULKAN();
  check_blur({{"widest aperture", 0.95f, 1.0f, 2.0f},
              {"narrowest aperture", 22.0f, 1.0f, 0.3f},
              {"near limit, behind", 2.0f, 0.2f, 0.3f},
              {"infinity, mid edge", 2.0f, kInfinity, 2.0f}},
             true);
}

// ---------------------------------------------------------------- scene files

std::string camera_json(const std::string &lens) {
  return R"({"render": {"width": 8, "height": 6, "samples": 4},
             "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1],
                        "focal_length_mm": 50, "sensor_width_mm": 36)" +
         lens + R"(},
             "materials": {"m": {"type": "emission", "radiance": [1, 1, 1]}},
             "objects": [{"type": "sphere", "center": [0, 0, -0.5], "radius": 0.1,
                          "material": "m"}]})";
}

TEST(LensExtremes, SceneFilesAcceptFocusNearerThanTheFocalLength) {
  const Scene scene = renderer::parse_scene(
      camera_json(R"(, "f_number": 22, "focus_distance_m": 0.02)"), "near.json");
  EXPECT_FLOAT_EQ(scene.camera.focus_distance_m, 0.02f);
  EXPECT_TRUE(test::all_layers_finite(test::render_cpu(scene, 4)));
}

TEST(LensExtremes, SceneFilesRejectFocusThatIsNoDistance) {
  const struct {
    const char *lens;
    const char *message;
  } cases[] = {
      {R"(, "f_number": 2, "focus_distance_m": 0)",
       "lens.json: camera.focus_distance_m: must be > 0 and <= 1e+06"},
      {R"(, "f_number": 2, "focus_distance_m": -1)",
       "lens.json: camera.focus_distance_m: must be > 0 and <= 1e+06"},
      {R"(, "f_number": 2, "focus_distance_m": 2e6)",
       "lens.json: camera.focus_distance_m: must be > 0 and <= 1e+06"},
      {R"(, "f_number": 2)", "lens.json: camera.focus_distance_m: missing"},
      {R"(, "f_number": -1, "focus_distance_m": 1)",
       "lens.json: camera.f_number: must be within 0 .. 1000"},
  };
  for (const auto &c : cases) {
    try {
      (void)renderer::parse_scene(camera_json(c.lens), "lens.json");
      ADD_FAILURE() << "accepted " << c.lens;
    } catch (const renderer::SceneError &e) {
      std::printf("rejected%s: %s\n", c.lens, e.what());
      EXPECT_EQ(std::string(e.what()), c.message);
    }
  }
}

// ---------------------------------------------------------------- pinhole

// f-number 0 is the pinhole: whatever the focus distance says (including
// values no scene file can hold), the frame is the pinhole frame bit for bit,
// on every layer, and the lens dimension of the sampler leaves the pixel,
// light and glass dimensions where they were.
TEST(LensExtremes, ApertureZeroIsThePinholeBitForBit) {
  Scene pinhole = stability::shaded_scene(64, 48);
  pinhole.camera.f_number = 0.0f;
  pinhole.camera.focus_distance_m = 0.0f; // as the loader leaves a pinhole
  const RenderResult reference = test::render_cpu(pinhole, 4);
  ASSERT_TRUE(test::all_layers_finite(reference));
  const float focus_values[] = {
      0.03f, 1.0f, 3.5f, 1e6f, kInfinity, -1.0f, std::numeric_limits<float>::quiet_NaN()};
  for (float focus : focus_values) {
    Scene s = pinhole;
    s.camera.focus_distance_m = focus;
    const RenderResult r = test::render_cpu(s, 4);
    EXPECT_TRUE(bit_identical(r, reference)) << "focus " << focus;
  }
  // A vanishing aperture converges to the pinhole (not bit for bit: the lens
  // ray is re-aimed at the focal plane).
  Scene narrow = pinhole;
  narrow.camera.f_number = 1000.0f; // the loader's limit
  narrow.camera.focus_distance_m = 3.5f;
  const double diff = test::rmse(test::render_cpu(narrow, 4).composite, reference.composite);
  std::printf("pinhole vs f/1000: composite RMSE %.3g\n", diff);
  EXPECT_LT(diff, 1e-3);
}

TEST(LensExtremes, ApertureZeroIsThePinholeBitForBitOnGpu) {
  CAMHEAD_REQUIRE_VULKAN();
  Scene pinhole = stability::shaded_scene(64, 48);
  pinhole.camera.f_number = 0.0f;
  pinhole.camera.focus_distance_m = 0.0f;
  const RenderResult reference = test::render_gpu(pinhole, 4);
  for (float focus : {0.03f, 3.5f, kInfinity}) {
    Scene s = pinhole;
    s.camera.focus_distance_m = focus;
    EXPECT_TRUE(bit_identical(test::render_gpu(s, 4), reference)) << "focus " << focus;
  }
}

// ---------------------------------------------------------------- frame parameters

// FrameParams made in code (the live pipeline maps lens encoders to them)
// can carry lens states that no scene file can: a defined result, never a
// NaN, and never a blank frame.
TEST(LensExtremes, DegenerateLensStatesInFrameParamsAreDefined) {
  Scene base = stability::shaded_scene(64, 48);
  base.camera.focus_distance_m = 1e6f;
  const RenderResult far_focus = test::render_cpu(base, 4);
  ASSERT_TRUE(test::all_layers_finite(far_focus));
  // Beyond the loader's 1e6 m, and +inf (lens_control's "infinity"): the
  // focal plane is put at 1e6 m, where every aperture point's ray is
  // parallel to the pinhole ray to within a micro-radian.
  for (float focus : {kInfinity, 1e30f, std::numeric_limits<float>::max()}) {
    Scene s = base;
    s.camera.focus_distance_m = focus;
    const renderer::gpu::FrameParams fp = renderer::make_frame_params(s, 4);
    std::printf("focus %g m -> FrameParams focus %g m\n", double(focus), double(fp.lens.y));
    EXPECT_TRUE(bit_identical(test::render_cpu(s, 4), far_focus)) << "focus " << focus;
  }
  // No focus (<= 0, NaN) with an aperture: the loader refuses such a file;
  // in code it keeps make_frame_params' 1 m stand-in and renders finite.
  for (float focus : {0.0f, -2.0f, std::numeric_limits<float>::quiet_NaN()}) {
    Scene s = base;
    s.camera.focus_distance_m = focus;
    EXPECT_TRUE(test::all_layers_finite(test::render_cpu(s, 4))) << "focus " << focus;
  }
  // Extreme but legal: a focal plane a micrometre away, an aperture wider
  // than the scene (f/0.01: radius 1.75 m), the narrowest the loader takes.
  const struct {
    float f_number, focus_m;
  } legal[] = {{2.8f, 1e-6f}, {2.8f, 1e-30f}, {0.01f, 3.5f}, {1000.0f, 0.05f}};
  for (const auto &l : legal) {
    Scene s = base;
    s.camera.f_number = l.f_number;
    s.camera.focus_distance_m = l.focus_m;
    const RenderResult r = test::render_cpu(s, 4);
    EXPECT_TRUE(test::all_layers_finite(r)) << "f/" << l.f_number << " focus " << l.focus_m;
  }
}

} // namespace
} // namespace camhead
