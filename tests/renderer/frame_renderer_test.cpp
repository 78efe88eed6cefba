// The renderer a frame at a time (frame_renderer.h): the camera frame goes in
// in its own pixel format and the composite comes out in each output's, and a
// pixel that nothing virtual touches leaves exactly as it came, whatever the
// format, or within one code value where the formats differ (4:2:2 to 4:2:0
// halves the vertical chroma: a mean of two codes rounds).
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <limits>
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
  scene.materials.push_back({"grey", MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}});
  scene.objects.push_back(test::plane("floor", {0.0f, -0.5f, -3.0f}, 20.0f, 0, true));
  scene.objects.push_back(test::box("crate", {0.3f, -0.3f, -2.0f}, glm::vec3(0.3f), 0, true));
  scene.lights.push_back(test::point_light({-1.0f, 2.0f, -1.0f}, 200.0f));
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

enum class Executor { cpu, gpu };

// The frame renderer of `executor`, or null (the test skips) without Vulkan.
std::unique_ptr<FrameRenderer> make_renderer(Executor executor, const Scene &scene) {
  if (executor == Executor::cpu)
    return make_cpu_frame_renderer(scene, 2);
  if (!test::have_vulkan())
    return nullptr;
  return make_gpu_frame_renderer(scene);
}

struct SameFormat {
  Executor executor;
  PixelFormat pixel;
  base::ColorRange range;
};

class FramePassThroughSameFormat : public ::testing::TestWithParam<SameFormat> {};

TEST_P(FramePassThroughSameFormat, EveryByteLeavesAsItCame) {
  const int w = 64, h = 48;
  const Scene scene = real_only(w, h);
  auto renderer = make_renderer(GetParam().executor, scene);
  if (!renderer)
    GTEST_SKIP() << "no Vulkan device";
  const VideoFormat f = format(GetParam().pixel, w, h, GetParam().range);
  const std::vector<std::uint8_t> plate = noise_frame(f, 7);
  const std::vector<std::uint8_t> out = render_through(*renderer, f, plate, f);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < plate.size(); ++i)
    differ += plate[i] != out[i];
  EXPECT_EQ(differ, 0u) << "of " << plate.size() << " bytes, " << base::describe(f);
}

std::vector<SameFormat> same_formats() {
  std::vector<SameFormat> all;
  for (const Executor e : {Executor::cpu, Executor::gpu})
    for (const auto &[pixel, range] : {std::pair{PixelFormat::yuyv, base::ColorRange::limited},
                                       std::pair{PixelFormat::yuyv, base::ColorRange::full},
                                       std::pair{PixelFormat::nv12, base::ColorRange::limited},
                                       std::pair{PixelFormat::rgb24, base::ColorRange::full},
                                       std::pair{PixelFormat::bgr24, base::ColorRange::full},
                                       std::pair{PixelFormat::xrgb8888, base::ColorRange::full}})
      all.push_back({e, pixel, range});
  return all;
}

INSTANTIATE_TEST_SUITE_P(Formats, FramePassThroughSameFormat, ::testing::ValuesIn(same_formats()),
                         [](const auto &param_info) {
                           const SameFormat &f = param_info.param;
                           return std::string(f.executor == Executor::cpu ? "cpu_" : "gpu_") +
                                  std::string(base::pixel_format_name(f.pixel)) +
                                  (f.range == base::ColorRange::full ? "_full" : "_limited");
                         });

class FramePassThrough : public ::testing::TestWithParam<Executor> {};

TEST_P(FramePassThrough, YuyvToNv12IsWithinOneCodeValue) {
  const int w = 64, h = 48;
  auto renderer = make_renderer(GetParam(), real_only(w, h));
  if (!renderer)
    GTEST_SKIP() << "no Vulkan device";
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

// A virtual ball in the top-left corner, no light for a shadow, no mirror.
Scene scene_with_ball(int w, int h, glm::vec3 ball) {
  Scene scene = real_only(w, h);
  scene.lights.clear();
  scene.materials.push_back({"blue", MaterialType::diffuse, glm::vec3(0.2f, 0.4f, 0.7f), 1.5f, {}});
  scene.materials.push_back({"glow", MaterialType::emission, glm::vec3(2.0f), 1.5f, {}});
  scene.objects.push_back(test::sphere("ball", ball, 0.2f, 2, false));
  return scene;
}

TEST_P(FramePassThrough, OnlyWhatTheVirtualObjectTouchesChanges) {
  // Nothing lights a shadow of the ball or shows it in a mirror: the rest
  // of the frame must be the camera's.
  const int w = 96, h = 64;
  const glm::vec3 ball(-1.2f, 0.7f, -3.0f);
  const Scene scene = scene_with_ball(w, h, ball);
  auto renderer = make_renderer(GetParam(), scene);
  if (!renderer)
    GTEST_SKIP() << "no Vulkan device";
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

// The influence region (influence_region.h) changes the cost, not the
// video: every byte of every output as when every pixel is traced, for
// outputs in the camera's format (which take the camera's bytes outside the
// region: 4:2:2, 4:2:0 with its chroma plane, 3-byte pixels, padded rows) and
// in another (converted everywhere), alone and beside a YUYV output, with a
// shadow and a mirror in the scene. The frame is large enough for the
// region's video groups to take more than one row of their list
// (gpu_tracer.cpp, dispatch_list).
TEST_P(FramePassThrough, InfluenceRegionGivesTheSameBytes) {
  const int w = 160, h = 96;
  Scene scene = scene_with_ball(w, h, {-0.6f, 0.1f, -2.5f});
  Light light;
  light.type = LightType::area;
  light.position = {-1.0f, 2.0f, -1.5f};
  light.normal = glm::normalize(glm::vec3(0.3f, -1.0f, -0.3f));
  light.power_W = 300.0f;
  scene.lights.push_back(light);
  scene.materials.push_back({"mirror", MaterialType::mirror, glm::vec3(0.9f), 1.5f, {}});
  scene.objects.push_back(test::box("mirror", {0.9f, 0.2f, -3.5f}, {0.5f, 0.8f, 0.05f},
                                    int(scene.materials.size()) - 1, true, {0.0f, -30.0f, 0.0f}));
  auto renderer = make_renderer(GetParam(), scene);
  if (!renderer)
    GTEST_SKIP() << "no Vulkan device";
  VideoFormat padded = format(PixelFormat::yuyv, w, h);
  padded.stride = 2 * w + 24;
  for (const VideoFormat &in : {format(PixelFormat::yuyv, w, h), format(PixelFormat::nv12, w, h),
                                format(PixelFormat::rgb24, w, h, base::ColorRange::full), padded}) {
    const std::vector<std::uint8_t> plate = noise_frame(in, 11);
    const std::vector<std::uint8_t> other_plate = noise_frame(in, 12);
    VideoFormat converted = format(PixelFormat::xrgb8888, w, h, base::ColorRange::full);
    if (in.pixel == PixelFormat::yuyv)
      converted = format(PixelFormat::nv12, w, h); // the camera's own beside it below
    for (const VideoFormat &out : {in, converted}) {
      const auto frame = [&](bool region, bool alone) {
        std::vector<VideoFormat> formats = {out};
        if (!alone)
          formats.push_back(format(PixelFormat::yuyv, w, h));
        std::vector<std::vector<std::uint8_t>> bytes;
        std::vector<VideoBuffer> targets;
        for (const VideoFormat &f : formats)
          bytes.emplace_back(base::frame_bytes(f), 0xAB);
        for (std::size_t i = 0; i < formats.size(); ++i)
          targets.push_back({formats[i], bytes[i]});
        FrameRequest request;
        request.camera = scene_camera(scene);
        request.rays_per_pixel = 4;
        // A frame of another camera image first, every pixel: what a frame
        // over the region failed to compute or convert would show its bytes,
        // not those of an identical frame before it.
        request.influence_region = false;
        EXPECT_EQ(renderer->render(request, {in, other_plate}, targets).status, FrameStatus::ok);
        request.influence_region = region;
        const FrameReport report = renderer->render(request, {in, plate}, targets);
        EXPECT_EQ(report.status, FrameStatus::ok) << report.detail;
        if (region)
          EXPECT_LT(report.traced_pixels, report.frame_pixels);
        else
          EXPECT_EQ(report.traced_pixels, report.frame_pixels);
        return bytes;
      };
      for (const bool alone : {true, false})
        EXPECT_TRUE(frame(true, alone) == frame(false, alone))
            << base::describe(in) << " in, " << base::describe(out) << " out"
            << (alone ? " alone" : " beside yuyv");
    }
  }
}

// The report names the region it traced (what the operator page shows):
// disjoint rectangles inside the frame, as many pixels as it says it
// traced, and every byte of the composite that is not the camera's lies in
// them. Without a region, one rectangle: the frame.
TEST_P(FramePassThrough, TheReportNamesTheRegionItTraced) {
  const int w = 160, h = 96;
  const Scene scene = scene_with_ball(w, h, {-0.6f, 0.1f, -2.5f});
  auto renderer = make_renderer(GetParam(), scene);
  if (!renderer)
    GTEST_SKIP() << "no Vulkan device";
  const VideoFormat yuyv = format(PixelFormat::yuyv, w, h);
  const std::vector<std::uint8_t> plate = noise_frame(yuyv, 5);
  std::vector<std::uint8_t> out(base::frame_bytes(yuyv));
  const VideoBuffer target{yuyv, out};
  FrameRequest request;
  request.camera = scene_camera(scene);
  request.rays_per_pixel = 4;
  FrameReport report = renderer->render(request, {yuyv, plate}, std::span(&target, 1));
  ASSERT_EQ(report.status, FrameStatus::ok) << report.detail;
  std::vector<int> covered(std::size_t(w * h), 0);
  for (const PixelRect &r : report.region) {
    ASSERT_TRUE(r.x0 < r.x1 && r.y0 < r.y1 && r.x1 <= std::uint32_t(w) && r.y1 <= std::uint32_t(h));
    for (std::uint32_t y = r.y0; y < r.y1; ++y)
      for (std::uint32_t x = r.x0; x < r.x1; ++x)
        ++covered[y * std::size_t(w) + x];
  }
  EXPECT_LE(report.region.size(), max_region_rects(w, h));
  EXPECT_EQ(std::count(covered.begin(), covered.end(), 1), std::ptrdiff_t(report.traced_pixels));
  EXPECT_EQ(std::count(covered.begin(), covered.end(), 2), 0) << "rectangles overlap";
  EXPECT_LT(report.traced_pixels, report.frame_pixels);
  std::size_t changed = 0, changed_outside = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int byte = 0; byte < 2; ++byte) {
        const std::size_t at = std::size_t(y) * base::row_bytes(yuyv) + std::size_t(2 * x + byte);
        if (out[at] != plate[at]) {
          ++changed;
          changed_outside += covered[std::size_t(y * w + x)] == 0;
        }
      }
  EXPECT_GT(changed, 100u) << "the ball changed nothing";
  EXPECT_EQ(changed_outside, 0u);

  request.influence_region = false;
  report = renderer->render(request, {yuyv, plate}, std::span(&target, 1));
  ASSERT_EQ(report.region.size(), 1u);
  EXPECT_EQ(report.region[0], (PixelRect{0, 0, std::uint32_t(w), std::uint32_t(h)}));
}

TEST_P(FramePassThrough, RefusesFramesOfAnotherSizeOrTooFewBytes) {
  auto renderer = make_renderer(GetParam(), real_only(32, 16));
  if (!renderer)
    GTEST_SKIP() << "no Vulkan device";
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
  // A plate-only frame is the camera frame: it needs one.
  request.plate_only = true;
  r = renderer->render(request, {right, {}}, std::span(&target, 1));
  EXPECT_EQ(r.status, FrameStatus::bad_input);
  EXPECT_NE(r.detail.find("plate-only frame without a camera frame"), std::string::npos)
      << r.detail;
  // A fraction of a ray is less than a ray, and a number.
  request.plate_only = false;
  request.extra_rays_per_pixel = 15.0f / 16.0f;
  EXPECT_EQ(renderer->render(request, {right, plate}, std::span(&target, 1)).status,
            FrameStatus::ok);
  for (const float extra : {1.0f, -0.25f, std::numeric_limits<float>::quiet_NaN()}) {
    request.extra_rays_per_pixel = extra;
    r = renderer->render(request, {right, plate}, std::span(&target, 1));
    EXPECT_EQ(r.status, FrameStatus::bad_input) << extra;
    EXPECT_NE(r.detail.find("a fraction of a ray a pixel"), std::string::npos) << r.detail;
  }
}

// A frame whose camera pose is not known yet (FrameRequest::plate_only) is
// the camera image, with the virtual ball in view: in the camera's format
// byte for byte, converted as a scene with nothing virtual converts it; and
// nothing is traced. The frame after it shows the ball again.
TEST_P(FramePassThrough, APlateOnlyFrameIsTheCameraImage) {
  const int w = 96, h = 64;
  const Scene scene = scene_with_ball(w, h, {-0.4f, 0.2f, -3.0f});
  auto renderer = make_renderer(GetParam(), scene);
  auto nothing_virtual = make_renderer(GetParam(), real_only(w, h));
  if (!renderer)
    GTEST_SKIP() << "no Vulkan device";
  const VideoFormat in = format(PixelFormat::yuyv, w, h);
  const std::vector<std::uint8_t> plate = noise_frame(in, 5);
  for (const VideoFormat &out : {in, format(PixelFormat::nv12, w, h),
                                 format(PixelFormat::xrgb8888, w, h, base::ColorRange::full)}) {
    SCOPED_TRACE(base::describe(out));
    const std::vector<std::uint8_t> expected = render_through(*nothing_virtual, in, plate, out);
    std::vector<std::uint8_t> bytes(base::frame_bytes(out), 0xAB);
    const VideoBuffer target{out, bytes};
    FrameRequest request;
    request.camera = scene_camera(scene);
    request.rays_per_pixel = 2;
    request.plate_only = true;
    const FrameReport report = renderer->render(request, {in, plate}, std::span(&target, 1));
    ASSERT_EQ(report.status, FrameStatus::ok) << report.detail;
    EXPECT_EQ(report.traced_pixels, 0u);
    EXPECT_EQ(report.camera_rays, 0u);
    EXPECT_TRUE(bytes == expected);
    request.plate_only = false;
    (void)renderer->render(request, {in, plate}, std::span(&target, 1));
    EXPECT_FALSE(bytes == expected) << "the ball must show in the frame after";
  }
}

// A virtual ball's shadow on a real floor whose camera pixels are darker
// than the proxy predicts (a near-black plate): I_c + I_m - I_r < 0 there,
// which limited range would carry as luma codes under 16 (reserved in SDI).
// The composite stops at black: the shadow reaches code 16 and no lower,
// and the camera pixels outside it pass through untouched.
TEST_P(FramePassThrough, AVirtualShadowStopsAtBlack) {
  const int w = 64, h = 48;
  Scene scene = real_only(w, h);
  scene.objects.push_back(test::sphere("ball", {-0.3f, -0.1f, -2.5f}, 0.35f, 0, false));
  auto renderer = make_renderer(GetParam(), scene);
  if (!renderer)
    GTEST_SKIP() << "no Vulkan device";
  const VideoFormat f = format(PixelFormat::yuyv, w, h);
  std::vector<std::uint8_t> plate(base::frame_bytes(f));
  for (std::size_t i = 0; i < plate.size(); i += 2) {
    plate[i] = 18;      // luma: just above black
    plate[i + 1] = 128; // neutral chroma
  }
  std::vector<std::uint8_t> out(plate.size());
  const VideoBuffer target{f, out};
  FrameRequest request;
  request.camera = scene_camera(scene);
  request.rays_per_pixel = 16;
  ASSERT_EQ(renderer->render(request, {f, plate}, std::span(&target, 1)).status, FrameStatus::ok);
  int darkest = 255;
  std::size_t shadowed = 0, unchanged = 0;
  for (std::size_t i = 0; i < out.size(); i += 2) {
    darkest = std::min<int>(darkest, out[i]);
    shadowed += out[i] == 16;
    unchanged += out[i] == 18;
  }
  EXPECT_EQ(darkest, 16) << "the shadow takes the floor to black, and not below";
  EXPECT_GT(shadowed, 20u) << "a shadow of some size";
  EXPECT_GT(unchanged, out.size() / 4) << "the floor away from the ball passes through";
}

INSTANTIATE_TEST_SUITE_P(Executors, FramePassThrough,
                         ::testing::Values(Executor::cpu, Executor::gpu),
                         [](const auto &param_info) {
                           return std::string(param_info.param == Executor::cpu ? "cpu" : "gpu");
                         });

// One model, two executors: the same frame in every output format from the
// CPU reference and the GPU tracer, within one code value (float rounding
// differs between a C++ compiler and a shader compiler; the rays are the
// same).
TEST(FrameExecutors, GpuAndCpuGiveTheSameCodes) {
  if (!test::have_vulkan())
    GTEST_SKIP() << "no Vulkan device";
  const int w = 96, h = 64;
  const Scene scene = scene_with_ball(w, h, {-0.2f, 0.1f, -2.5f});
  auto cpu = make_cpu_frame_renderer(scene, 2);
  auto gpu = make_gpu_frame_renderer(scene);
  const VideoFormat in = format(PixelFormat::nv12, w, h);
  const std::vector<std::uint8_t> plate = noise_frame(in, 9);
  for (const PixelFormat pixel : {PixelFormat::yuyv, PixelFormat::nv12, PixelFormat::rgb24,
                                  PixelFormat::bgr24, PixelFormat::xrgb8888}) {
    const VideoFormat out = format(pixel, w, h);
    const std::vector<std::uint8_t> a = render_through(*cpu, in, plate, out, 8);
    const std::vector<std::uint8_t> b = render_through(*gpu, in, plate, out, 8);
    int worst = 0;
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      worst = std::max(worst, std::abs(int(a[i]) - int(b[i])));
      differ += a[i] != b[i];
    }
    EXPECT_LE(worst, 1) << base::pixel_format_name(pixel);
    EXPECT_LT(differ, a.size() / 100) << base::pixel_format_name(pixel) << ": " << differ << " of "
                                      << a.size() << " bytes differ";
  }
}

// A frame for several outputs writes each in its own format, exactly as a
// frame for that output alone (the GPU encodes them one dispatch each).
TEST(FrameExecutors, EachOutputOfAFrameIsItsOwnFormat) {
  const int w = 96, h = 64;
  const Scene scene = scene_with_ball(w, h, {-0.2f, 0.1f, -2.5f});
  for (const Executor e : {Executor::cpu, Executor::gpu}) {
    auto renderer = make_renderer(e, scene);
    if (!renderer)
      continue;
    const VideoFormat in = format(PixelFormat::yuyv, w, h);
    const std::vector<std::uint8_t> plate = noise_frame(in, 5);
    const std::array<PixelFormat, 3> pixels = {PixelFormat::nv12, PixelFormat::xrgb8888,
                                               PixelFormat::bgr24};
    std::vector<std::vector<std::uint8_t>> together;
    std::vector<VideoBuffer> targets;
    for (const PixelFormat pixel : pixels)
      together.emplace_back(base::frame_bytes(format(pixel, w, h)), 0xAB);
    for (std::size_t k = 0; k < pixels.size(); ++k)
      targets.push_back({format(pixels[k], w, h), together[k]});
    FrameRequest request;
    request.camera = scene_camera(scene);
    request.rays_per_pixel = 4;
    const FrameReport report = renderer->render(request, {in, plate}, targets);
    ASSERT_EQ(report.status, FrameStatus::ok) << report.detail;
    for (std::size_t k = 0; k < pixels.size(); ++k) {
      std::vector<std::uint8_t> alone(together[k].size(), 0xAB);
      const VideoBuffer target{targets[k].format, alone};
      ASSERT_EQ(renderer->render(request, {in, plate}, std::span(&target, 1)).status,
                FrameStatus::ok);
      EXPECT_TRUE(together[k] == alone)
          << (e == Executor::cpu ? "cpu " : "gpu ") << base::pixel_format_name(pixels[k]);
    }
  }
}

// Rows padded beyond their pixels (a V4L2 driver's bytesperline) are read
// and written as such, and the padding is left alone.
TEST(FrameExecutors, PaddedRowsPassThrough) {
  const int w = 64, h = 32;
  for (const Executor e : {Executor::cpu, Executor::gpu}) {
    auto renderer = make_renderer(e, real_only(w, h));
    if (!renderer)
      continue;
    VideoFormat f = format(PixelFormat::nv12, w, h);
    f.stride = w + 32;
    const std::vector<std::uint8_t> plate = noise_frame(f, 4);
    const std::vector<std::uint8_t> out = render_through(*renderer, f, plate, f);
    std::size_t differ = 0, padding_touched = 0;
    for (std::size_t row = 0; row < std::size_t(h) * 3 / 2; ++row)
      for (std::size_t x = 0; x < std::size_t(f.stride); ++x) {
        const std::size_t i = row * std::size_t(f.stride) + x;
        if (x < std::size_t(w))
          differ += plate[i] != out[i];
        else
          padding_touched += out[i] != 0xAB;
      }
    EXPECT_EQ(differ, 0u) << (e == Executor::cpu ? "cpu" : "gpu");
    EXPECT_EQ(padding_touched, 0u) << (e == Executor::cpu ? "cpu" : "gpu");
  }
}

} // namespace
} // namespace camhead::renderer
