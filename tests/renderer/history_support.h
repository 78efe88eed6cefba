// What the tests of the live frame's history share (frame_history_test.cpp,
// reprojection_test.cpp): a small scene of blur, shadow and depth edges, and
// a renderer of it frame after frame with a camera frame of its own.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <span>
#include <vector>

#include <glm/vec4.hpp>

#include "camhead/base/video_format.h"
#include "camhead/renderer/frame_renderer.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead::renderer::history {

inline constexpr int kWidth = 64;
inline constexpr int kHeight = 48;

// A virtual ball defocused in front of a real crate on a real floor, lit by
// a point light: blur, a shadow on the proxy, and a depth edge.
inline Scene ball_scene() {
  Scene scene = test::empty_scene("history", 2.0f, 2.0f, kWidth, kHeight);
  scene.materials.push_back({"grey", MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}});
  scene.materials.push_back({"blue", MaterialType::diffuse, glm::vec3(0.2f, 0.4f, 0.7f), 1.5f, {}});
  scene.objects.push_back(test::plane("floor", {0.0f, -0.5f, -3.0f}, 20.0f, 0, true));
  scene.objects.push_back(test::box("crate", {0.3f, -0.3f, -3.0f}, glm::vec3(0.4f), 0, true));
  scene.objects.push_back(test::sphere("ball", {-0.2f, -0.25f, -1.2f}, 0.2f, 1, false));
  scene.lights.push_back(test::point_light({-1.0f, 2.0f, -1.0f}, 200.0f));
  return scene;
}

// The same focused at 0.3 m at f/1: everything else blurred by 5 to 7
// pixels (radius), as the rig's near focus blurs its scene at 720x576.
inline Scene defocused_ball_scene() {
  Scene scene = ball_scene();
  scene.camera.focus_distance_m = 0.3f;
  scene.camera.f_number = 1.0f;
  return scene;
}

inline base::VideoFormat rgb24() {
  base::VideoFormat f;
  f.pixel = base::PixelFormat::rgb24;
  f.width = kWidth;
  f.height = kHeight;
  f.range = base::ColorRange::full;
  return f;
}

inline std::vector<std::uint8_t> camera_frame() {
  std::vector<std::uint8_t> bytes(base::frame_bytes(rgb24()));
  std::mt19937 rng(11);
  for (std::uint8_t &b : bytes)
    b = std::uint8_t(64 + rng() % 128);
  return bytes;
}

enum class Executor { cpu, gpu };

// Renders frames with one renderer and keeps what the last one gave: RGB,
// the camera's format, and with `and_yuyv` a YUYV output too, which makes
// the renderer resolve every pixel rather than copy the camera's bytes
// outside the influence region. The GPU executor's needs Vulkan (its tests
// skip without; available() says).
class Frames {
public:
  explicit Frames(const Scene &scene, bool and_yuyv = false, Executor executor = Executor::cpu,
                  int cpu_threads = 2)
      : renderer_(executor == Executor::cpu ? make_cpu_frame_renderer(scene, cpu_threads)
                  : test::have_vulkan()     ? make_gpu_frame_renderer(scene)
                                            : nullptr),
        and_yuyv_(and_yuyv) {}
  [[nodiscard]] bool available() const { return renderer_ != nullptr; }

  FrameReport render(const FrameRequest &request) {
    out_.assign(base::frame_bytes(rgb24()), 0);
    base::VideoFormat yuyv = rgb24();
    yuyv.pixel = base::PixelFormat::yuyv;
    yuyv.range = base::ColorRange::limited;
    yuyv_.assign(base::frame_bytes(yuyv), 0);
    const VideoBuffer targets[] = {{rgb24(), out_}, {yuyv, yuyv_}};
    const FrameReport report =
        renderer_->render(request, {rgb24(), plate_}, std::span(targets, and_yuyv_ ? 2 : 1));
    EXPECT_EQ(report.status, FrameStatus::ok) << report.detail;
    return report;
  }
  [[nodiscard]] const std::vector<std::uint8_t> &out() const { return out_; }
  // The last frame's composite, linear RGB, before the outputs' rounding.
  [[nodiscard]] std::span<const glm::vec4> composite() const { return renderer_->last_composite(); }

private:
  std::unique_ptr<FrameRenderer> renderer_;
  bool and_yuyv_;
  std::vector<std::uint8_t> plate_ = camera_frame();
  std::vector<std::uint8_t> out_, yuyv_;
};

inline FrameRequest still(const Scene &scene, std::uint32_t rpp, std::uint32_t seed = 5) {
  FrameRequest request;
  request.camera = scene_camera(scene);
  request.rays_per_pixel = rpp;
  request.seed = seed;
  request.accumulation.enabled = true;
  return request;
}

// Every pixel alike, frame after frame.
inline FrameRequest still_uniform(const Scene &scene, std::uint32_t rpp, std::uint32_t seed = 5) {
  FrameRequest request = still(scene, rpp, seed);
  request.accumulation.share_by_noise = false;
  return request;
}

inline std::size_t bytes_differing(const std::vector<std::uint8_t> &a,
                                   const std::vector<std::uint8_t> &b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    n += a[i] != b[i];
  return n;
}

// The relative RMSE of `frames`' last output against `reference`'s, over
// every byte (outside the influence region both are the camera's: the
// errors are diluted alike).
inline double virtual_error(const Frames &frames, const Frames &reference) {
  double diff = 0.0, ref = 0.0;
  for (std::size_t i = 0; i < reference.out().size(); ++i) {
    const double a = reference.out()[i], b = frames.out()[i];
    diff += (a - b) * (a - b);
    ref += a * a;
  }
  return std::sqrt(diff / ref);
}

// A converged render of `scene` (1024 samples), to measure against.
inline Frames converged(const Scene &scene, std::uint32_t seed) {
  Frames reference(scene);
  FrameRequest request = still_uniform(scene, 1024, seed);
  request.accumulation.max_samples = 1024;
  (void)reference.render(request);
  return reference;
}

} // namespace camhead::renderer::history
