// The renderer a frame at a time (frame_renderer.h): the camera frame goes in
// in its own pixel format and the composite comes out in each output's, and a
// pixel that nothing virtual touches leaves exactly as it came, whatever the
// format, or within one code value where the formats differ (4:2:2 to 4:2:0
// halves the vertical chroma: a mean of two codes rounds).
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "camhead/base/video_format.h"
#include "camhead/renderer/frame_renderer.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

using base::PixelFormat;
using base::VideoFormat;

VideoFormat format(PixelFormat pixel, int w, int h,
                   base::ColorRange range = base::ColorRange::limited) {
  VideoFormat f;
  f.pixel = pixel;
  f.width = w;
  f.height = h;
  f.range = range;
  return f;
}

// Every code value, in an order that puts unrelated ones side by side (and
// so Y'CbCr triples far outside the RGB cube).
std::vector<std::uint8_t> noise_frame(const VideoFormat &f, unsigned seed) {
  std::vector<std::uint8_t> bytes(base::frame_bytes(f));
  std::mt19937 rng(seed);
  for (std::uint8_t &b : bytes)
    b = std::uint8_t(rng());
  if (f.pixel == PixelFormat::xrgb8888)
    for (std::size_t i = 3; i < bytes.size(); i += 4)
      bytes[i] = 0xff; // X is not a colour
  return bytes;
}

// A scene with nothing virtual: every pixel must pass through.
Scene real_only(int w, int h) {
  Scene scene = test::empty_scene("real only", 2.0f, 2.0f, w, h);
  scene.materials.push_back({"grey", MaterialType::diffuse, glm::vec3(0.5f), 1.5f});
  scene.objects.push_back(test::plane("floor", {0.0f, -0.5f, -3.0f}, 20.0f, 0, true));
  scene.objects.push_back(test::box("crate", {0.3f, -0.3f, -2.0f}, glm::vec3(0.3f), 0, true));
  Light light;
  light.type = LightType::point;
  light.position = {-1.0f, 2.0f, -1.0f};
  light.power_W = 200.0f;
  scene.lights.push_back(light);
  return scene;
}

std::vector<std::uint8_t> render_through(FrameRenderer &renderer, const VideoFormat &in,
                                         const std::vector<std::uint8_t> &plate,
                                         const VideoFormat &out, std::uint32_t rpp = 2) {
  std::vector<std::uint8_t> bytes(base::frame_bytes(out), 0xAB);
  const VideoBuffer target{out, bytes};
  FrameRequest request;
  request.camera = scene_camera(real_only(in.width, in.height));
  request.rays_per_pixel = rpp;
  const FrameReport report = renderer.render(request, {in, plate}, std::span(&target, 1));
  EXPECT_EQ(report.status, FrameStatus::ok) << report.detail;
  return bytes;
}

struct SameFormat {
  PixelFormat pixel;
  base::ColorRange range;
};

class FramePassThroughSameFormat : public ::testing::TestWithParam<SameFormat> {};

TEST_P(FramePassThroughSameFormat, EveryByteLeavesAsItCame) {
  const int w = 64, h = 48;
  const Scene scene = real_only(w, h);
  auto renderer = make_cpu_frame_renderer(scene, 2);
  const VideoFormat f = format(GetParam().pixel, w, h, GetParam().range);
  const std::vector<std::uint8_t> plate = noise_frame(f, 7);
  const std::vector<std::uint8_t> out = render_through(*renderer, f, plate, f);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < plate.size(); ++i)
    differ += plate[i] != out[i];
  EXPECT_EQ(differ, 0u) << "of " << plate.size() << " bytes, " << base::describe(f);
}

INSTANTIATE_TEST_SUITE_P(Formats, FramePassThroughSameFormat,
                         ::testing::Values(SameFormat{PixelFormat::yuyv, base::ColorRange::limited},
                                           SameFormat{PixelFormat::yuyv, base::ColorRange::full},
                                           SameFormat{PixelFormat::nv12, base::ColorRange::limited},
                                           SameFormat{PixelFormat::rgb24, base::ColorRange::full},
                                           SameFormat{PixelFormat::bgr24, base::ColorRange::full},
                                           SameFormat{PixelFormat::xrgb8888,
                                                      base::ColorRange::full}),
                         [](const auto &param_info) {
                           return std::string(base::pixel_format_name(param_info.param.pixel)) +
                                  (param_info.param.range == base::ColorRange::full ? "_full"
                                                                                    : "_limited");
                         });

TEST(FramePassThrough, YuyvToNv12IsWithinOneCodeValue) {
  const int w = 64, h = 48;
  auto renderer = make_cpu_frame_renderer(real_only(w, h), 2);
  const VideoFormat in = format(PixelFormat::yuyv, w, h);
  const VideoFormat out = format(PixelFormat::nv12, w, h);
  // In-gamut content: a YUYV frame made from an NV12-compatible one would
  // be circular; any codes will do, the bound is on the chroma mean.
  const std::vector<std::uint8_t> plate = noise_frame(in, 11);
  const std::vector<std::uint8_t> got = render_through(*renderer, in, plate, out);
  int worst_luma = 0, worst_chroma = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int expect = plate[std::size_t(y) * 2 * w + 2 * x];
      worst_luma = std::max(worst_luma, std::abs(got[std::size_t(y) * w + x] - expect));
    }
  for (int y = 0; y < h; y += 2)
    for (int x = 0; x < w; x += 2)
      for (int c = 0; c < 2; ++c) {
        // 4:2:2 chroma of the two rows, averaged.
        const int a = plate[std::size_t(y) * 2 * w + 2 * x + 1 + 2 * c];
        const int b = plate[std::size_t(y + 1) * 2 * w + 2 * x + 1 + 2 * c];
        const int got_c = got[std::size_t(w) * h + std::size_t(y / 2) * w + x + c];
        worst_chroma = std::max(worst_chroma, std::abs(2 * got_c - (a + b)));
      }
  EXPECT_EQ(worst_luma, 0);
  EXPECT_LE(worst_chroma, 1) << "twice the code against the sum of the two rows' codes";
}

TEST(FramePassThrough, OnlyWhatTheVirtualObjectTouchesChanges) {
  // A virtual ball in the top-left corner, no light to cast its shadow, no
  // mirror to show it: the rest of the frame must be the camera's.
  const int w = 96, h = 64;
  Scene scene = real_only(w, h);
  scene.lights.clear();
  scene.materials.push_back({"blue", MaterialType::diffuse, glm::vec3(0.2f, 0.4f, 0.7f), 1.5f});
  scene.materials.push_back({"glow", MaterialType::emission, glm::vec3(2.0f), 1.5f});
  const glm::vec3 ball(-1.2f, 0.7f, -3.0f);
  scene.objects.push_back(test::sphere("ball", ball, 0.2f, 2, false));
  auto renderer = make_cpu_frame_renderer(scene, 2);
  const VideoFormat f = format(PixelFormat::yuyv, w, h);
  const std::vector<std::uint8_t> plate = noise_frame(f, 3);
  const std::vector<std::uint8_t> out = render_through(*renderer, f, plate, f, 4);
  // The ball's projection grown by its blur circle and a pixel pair.
  const glm::vec2 centre = test::project(scene, ball);
  const double reach = 0.2 * 50.0 * w / 36.0 / 3.0 + test::coc_px(scene, 3.0f) / 2 + 3;
  std::size_t changed_inside = 0, changed_outside = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool near = glm::length(glm::vec2(x, y) - centre) < reach;
      for (int b = 0; b < 2; ++b) {
        const std::size_t i = std::size_t(y) * 2 * w + 2 * x + b;
        (near ? changed_inside : changed_outside) += plate[i] != out[i];
      }
    }
  EXPECT_EQ(changed_outside, 0u);
  EXPECT_GT(changed_inside, 20u) << "the ball must show";
}

TEST(FrameRenderer, RefusesFramesOfAnotherSizeOrTooFewBytes) {
  auto renderer = make_cpu_frame_renderer(real_only(32, 16), 1);
  const VideoFormat right = format(PixelFormat::yuyv, 32, 16);
  const VideoFormat wrong = format(PixelFormat::yuyv, 16, 16);
  std::vector<std::uint8_t> plate(base::frame_bytes(right), 128), out(base::frame_bytes(right));
  const VideoBuffer target{right, out};
  FrameRequest request;
  request.camera = scene_camera(real_only(32, 16));
  FrameReport r = renderer->render(request, {wrong, plate}, std::span(&target, 1));
  EXPECT_EQ(r.status, FrameStatus::bad_input);
  EXPECT_NE(r.detail.find("not the render size 32x16"), std::string::npos) << r.detail;
  r = renderer->render(request, {right, std::span(plate).first(100)}, std::span(&target, 1));
  EXPECT_EQ(r.status, FrameStatus::bad_input);
  EXPECT_NE(r.detail.find("needs 1024 bytes"), std::string::npos) << r.detail;
  const VideoBuffer small{right, std::span(out).first(10)};
  r = renderer->render(request, {right, plate}, std::span(&small, 1));
  EXPECT_EQ(r.status, FrameStatus::bad_input);
  EXPECT_NE(r.detail.find("output"), std::string::npos) << r.detail;
}

} // namespace
} // namespace camhead::renderer
