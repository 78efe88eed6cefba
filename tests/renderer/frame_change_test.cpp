// How far a change of the camera moves the picture (frame_history.h,
// frame_change_px), which decides whether a history goes on: the largest
// move of a blur circle or a point, through a pinhole and through a lens
// model.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/frame_history.h"
#include "camhead/renderer/frame_settings.h"
#include "history_support.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

using namespace history;

TEST(FrameChange, IsTheLargestMoveOfABlurCircleOrAPoint) {
  const Scene scene = ball_scene();
  const CompiledScene compiled = compile_scene(scene);
  const FrameCamera camera = scene_camera(scene);
  const gpu::FrameParams a = make_frame_params(scene, camera);
  const double nearest = nearest_depth_m(compiled, a);
  EXPECT_EQ(frame_change_px(a, a, nearest), 0.0);

  // Focus 2 m -> 3 m at f/2: every radius changes by f A (1/2 - 1/3) (the
  // test helper's diameter at infinity, halved), whatever the depth.
  FrameCamera refocused = camera;
  refocused.focus_distance_m = 3.0f;
  Scene refocused_scene = scene;
  refocused_scene.camera.focus_distance_m = 3.0f;
  const double expected =
      0.5 * std::abs(test::coc_px(scene, 1e9f) - test::coc_px(refocused_scene, 1e9f));
  EXPECT_NEAR(frame_change_px(a, make_frame_params(scene, refocused), nearest), expected,
              1e-3 * expected);

  // A turn of the view by theta moves the point on the axis by f theta
  // pixels; the bound is at least that, and not many times more (points off
  // the axis move by up to f theta (1 + tan^2), and their blur changes).
  const auto turn_by = [&](double theta) {
    FrameCamera turned = camera;
    const glm::vec3 view = camera.look_at - camera.position;
    const float c = float(std::cos(theta)), s = float(std::sin(theta));
    turned.look_at =
        camera.position + glm::vec3(c * view.x - s * view.z, view.y, s * view.x + c * view.z);
    return frame_change_px(a, make_frame_params(scene, turned), nearest);
  };
  const double f = a.lens.z;
  for (const double theta : {1e-4, 1e-3, 1e-2}) {
    EXPECT_GE(turn_by(theta), 0.99 * f * theta) << theta;
    EXPECT_LE(turn_by(theta), 3.0 * f * theta) << theta;
  }
}

// Through a lens model: another lens is another picture (no tolerance
// covers it), and a change of focus is bounded as the pinhole's times the
// most the lens stretches the image plane, which a barrel lens does at its
// centre (1 + nothing) and a pincushion towards its corners: the bound is
// at least the largest move of a blur circle's radius measured there.
TEST(FrameChange, ThroughALensModel) {
  const Scene scene = ball_scene();
  const CompiledScene compiled = compile_scene(scene);
  FrameCamera camera = scene_camera(scene);
  camera.lens_model.k1 = 0.2f; // pincushion: the corners are stretched
  const gpu::FrameParams a = make_frame_params(scene, camera);
  const double nearest = nearest_depth_m(compiled, a);
  EXPECT_EQ(frame_change_px(a, a, nearest), 0.0);
  FrameCamera other = camera;
  other.lens_model.k1 = 0.2001f;
  EXPECT_EQ(frame_change_px(a, make_frame_params(scene, other), nearest), INFINITY);
  FrameCamera pinhole = camera;
  pinhole.lens_model = {};
  EXPECT_EQ(frame_change_px(a, make_frame_params(scene, pinhole), nearest), INFINITY);

  // Refocused: the rim of a blur circle in a corner, where the pincushion
  // stretches the image most, moves by no more than the bound, and not by
  // far less.
  FrameCamera refocused = camera;
  refocused.focus_distance_m = 3.0f;
  const gpu::FrameParams b = make_frame_params(scene, refocused);
  const double bound = frame_change_px(a, b, nearest);
  double largest = 0.0;
  const glm::vec2 corner_ideal = pixel_to_ideal(a, glm::vec2(0.0f));
  const glm::vec2 outward = glm::normalize(corner_ideal);
  for (const double depth : {nearest, 1.0, 4.0, 1e3}) {
    const auto rim = [&](const gpu::FrameParams &f) {
      const double radius = double(f.lens.x) * std::abs(1.0 / depth - 1.0 / double(f.lens.y));
      return ideal_to_pixel(f, corner_ideal + float(radius) * outward);
    };
    largest = std::max(largest, double(glm::length(rim(b) - rim(a))));
  }
  std::printf("a pincushion's corner: a blur rim moves %.2f px on refocusing, bound %.2f px\n",
              largest, bound);
  EXPECT_LE(largest, bound);
  EXPECT_GT(largest, 0.3 * bound);
}

} // namespace
} // namespace camhead::renderer
