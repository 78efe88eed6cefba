// frame_renderer.h promises that a live frame allocates nothing: a counting
// operator new for this test binary holds the CPU reference to it, on every
// thread, for frames of a held shot (the history growing, its rays shared
// by noise, the reconstruction on) after the first few.
//
// Not held yet, and so not tested: a frame that starts a new history (a
// focus pull) builds its influence region, which allocates
// (influence_region.cpp builds vectors of half-spaces and polyhedra); the
// GPU executor builds it every frame.
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <span>
#include <vector>

#include "camhead/base/video_format.h"
#include "camhead/renderer/frame_renderer.h"
#include "test_scenes.h"

#include <gtest/gtest.h>

// GCC takes the replaced delete's free() for a mismatch with the new that it
// cannot see is replaced too.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

namespace {

std::atomic<bool> counting{false};
std::atomic<std::uint64_t> allocations{0};

} // namespace

// The replacements count while `counting` is on, on whatever thread. Every
// unaligned form is replaced, so that whatever the process allocates with
// one (a sanitizer's runtime, lavapipe's LLVM) it frees with its own kind;
// the aligned forms stay the library's, a matched pair.
namespace {

void *counted(std::size_t bytes) noexcept {
  if (counting.load(std::memory_order_relaxed))
    allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(bytes == 0 ? 1 : bytes);
}

void *counted_or_throw(std::size_t bytes) {
  if (void *p = counted(bytes))
    return p;
  throw std::bad_alloc();
}

} // namespace

void *operator new(std::size_t bytes) {
  return counted_or_throw(bytes);
}
void *operator new[](std::size_t bytes) {
  return counted_or_throw(bytes);
}
void *operator new(std::size_t bytes, const std::nothrow_t &) noexcept {
  return counted(bytes);
}
void *operator new[](std::size_t bytes, const std::nothrow_t &) noexcept {
  return counted(bytes);
}
void operator delete(void *p) noexcept {
  std::free(p);
}
void operator delete[](void *p) noexcept {
  std::free(p);
}
void operator delete(void *p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void *p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void *p, const std::nothrow_t &) noexcept {
  std::free(p);
}
void operator delete[](void *p, const std::nothrow_t &) noexcept {
  std::free(p);
}

namespace camhead::renderer {
namespace {

TEST(FrameAllocations, AHeldShotAllocatesNothingFrameAfterFrame) {
  Scene scene = test::empty_scene("allocations", 1.4f, 0.8f, 96, 64);
  scene.materials.push_back({"grey", MaterialType::diffuse, glm::vec3(0.5f), 1.5f});
  scene.objects.push_back(test::plane("floor", {0.0f, -0.5f, -3.0f}, 20.0f, 0, true));
  scene.objects.push_back(test::sphere("ball", {-0.2f, -0.25f, -1.5f}, 0.25f, 0, false));
  Light light;
  light.type = LightType::point;
  light.position = {-1.0f, 2.0f, -1.0f};
  light.power_W = 200.0f;
  scene.lights.push_back(light);
  auto renderer = make_cpu_frame_renderer(scene, 2);

  base::VideoFormat yuyv;
  yuyv.width = 96;
  yuyv.height = 64;
  base::VideoFormat nv12 = yuyv;
  nv12.pixel = base::PixelFormat::nv12;
  const std::vector<std::uint8_t> plate(base::frame_bytes(yuyv), 128);
  std::vector<std::uint8_t> out_yuyv(base::frame_bytes(yuyv)), out_nv12(base::frame_bytes(nv12));
  const VideoBuffer outputs[] = {{yuyv, out_yuyv}, {nv12, out_nv12}};
  FrameRequest request;
  request.camera = scene_camera(scene);
  request.rays_per_pixel = 2;
  request.accumulation.enabled = true;

  const auto frames = [&](int n) {
    for (int k = 0; k < n; ++k) {
      request.seed = std::uint32_t(k + 1);
      const FrameReport report = renderer->render(request, {yuyv, plate}, outputs);
      ASSERT_EQ(report.status, FrameStatus::ok) << report.detail;
    }
  };
  frames(3); // the history starts, the region is built: warm-up
  counting = true;
  frames(20);
  counting = false;
  EXPECT_EQ(allocations.load(), 0u);

  // The count works: a frame that moves the lens builds a region.
  request.camera.focus_distance_m = 2.0f;
  counting = true;
  frames(1);
  counting = false;
  EXPECT_GT(allocations.load(), 0u);
}

} // namespace
} // namespace camhead::renderer
