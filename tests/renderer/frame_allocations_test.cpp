// frame_renderer.h promises that a live frame allocates nothing: a counting
// operator new for this test binary holds both executors to it from the
// first frame after prepare(), for a held shot (the history growing, its
// rays shared by noise, the reconstruction on) and for a shot that moves
// every frame (a focus pull with a pan: a new history and influence region
// each frame; without the pan, each frame's history starts with the frames
// before it moved through the new focus). On the GPU, a pipeline built in a
// frame would count too.
//
// Counted (tests/support/counting_new.h): C++ allocations, not the C
// library's malloc. The CPU reference is counted on every thread (its
// workers too); the GPU executor on the thread that renders, as the
// driver's own threads are not camhead's: lavapipe (Mesa 22.3.6)
// JIT-compiles an LLVM module on its queue thread for every frame whose
// camera frame it decodes, about 130 C++ allocations a frame (an empty
// decode kernel too; bench/RESULTS.md).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "camhead/base/video_format.h"
#include "camhead/renderer/frame_renderer.h"
#include "counting_new.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace {

// The calling thread is the one that renders (the GPU executor's count).
thread_local bool rendering_thread = false;

} // namespace

namespace camhead::renderer {
namespace {

// A floor, a virtual ball casting a shadow on it, a light: every pass of a
// frame has work.
Scene ball_scene() {
  Scene scene = test::empty_scene("allocations", 1.4f, 0.8f, 96, 64);
  scene.materials.push_back({"grey", MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}});
  scene.objects.push_back(test::plane("floor", {0.0f, -0.5f, -3.0f}, 20.0f, 0, true));
  scene.objects.push_back(test::sphere("ball", {-0.2f, -0.25f, -1.5f}, 0.25f, 0, false));
  scene.lights.push_back(test::point_light({-1.0f, 2.0f, -1.0f}, 200.0f));
  return scene;
}

enum class Executor { cpu, gpu };

// A renderer of ball_scene() with a plate and two outputs (the camera's
// format and another), rendering accumulating frames; without a renderer
// on a machine without Vulkan.
class LiveFrames {
public:
  explicit LiveFrames(Executor executor)
      : executor_(executor), scene_(ball_scene()),
        renderer_(executor == Executor::cpu ? make_cpu_frame_renderer(scene_, 2)
                  : test::have_vulkan()     ? make_gpu_frame_renderer(scene_)
                                            : nullptr),
        plate_(base::frame_bytes(yuyv()), 128), out_yuyv_(base::frame_bytes(yuyv())),
        out_nv12_(base::frame_bytes(nv12())) {
    request.camera = scene_camera(scene_);
    request.rays_per_pixel = 2;
    request.accumulation.enabled = true;
  }

  // What the run loop does before its first frame.
  void prepare() {
    const base::VideoFormat outputs[] = {yuyv(), nv12()};
    renderer_->prepare(request, yuyv(), outputs);
  }

  // Renders a frame; `move` changes the request first.
  template <typename Move> void frames(int n, Move move) {
    for (int k = 0; k < n; ++k) {
      request.seed = std::uint32_t(++frame_);
      move(frame_);
      const VideoBuffer outputs[] = {{yuyv(), out_yuyv_}, {nv12(), out_nv12_}};
      const FrameReport report =
          renderer_->render(request, {yuyv(), plate_}, std::span(outputs, output_count));
      ASSERT_EQ(report.status, FrameStatus::ok) << report.detail;
      reprojected += report.reprojected_samples;
    }
  }
  void frames(int n) {
    frames(n, [](int) {});
  }
  [[nodiscard]] bool available() const { return renderer_ != nullptr; }

  // Allocations while `run` runs, on the threads that are the executor's.
  template <typename Run> std::uint64_t allocations_in(Run run) {
    rendering_thread = true;
    test::counting_new::start(executor_ == Executor::cpu
                                  ? test::counting_new::Classifier([] { return 0; })
                                  : [] { return rendering_thread ? 0 : -1; });
    run();
    test::counting_new::stop();
    return test::counting_new::count(0);
  }

  FrameRequest request;
  std::size_t output_count = 2;  // of the two that prepare() names
  std::uint64_t reprojected = 0; // samples, in all frames

private:
  static base::VideoFormat yuyv() {
    base::VideoFormat f;
    f.width = 96;
    f.height = 64;
    return f;
  }
  static base::VideoFormat nv12() {
    base::VideoFormat f = yuyv();
    f.pixel = base::PixelFormat::nv12;
    return f;
  }

  Executor executor_;
  Scene scene_;
  std::unique_ptr<FrameRenderer> renderer_;
  std::vector<std::uint8_t> plate_, out_yuyv_, out_nv12_;
  int frame_ = 0;
};

class FrameAllocations : public ::testing::TestWithParam<Executor> {};

TEST_P(FrameAllocations, AHeldShotAllocatesNothingFrameAfterFrame) {
  LiveFrames live(GetParam());
  if (!live.available())
    GTEST_SKIP() << "no Vulkan device";
  live.prepare();
  EXPECT_EQ(live.allocations_in([&] { live.frames(20); }), 0u);
}

// A frame may have no output at all (the renderer takes an empty list):
// prepared for two, it still builds nothing.
TEST_P(FrameAllocations, AFrameWithoutOutputsAllocatesNothing) {
  LiveFrames live(GetParam());
  if (!live.available())
    GTEST_SKIP() << "no Vulkan device";
  live.prepare();
  live.output_count = 0;
  EXPECT_EQ(live.allocations_in([&] { live.frames(4); }), 0u);
}

// Frame k of a focus pull with a pan from `rest`: every frame beyond the
// tolerance, a new history and region each time.
auto pull_and_pan(LiveFrames &live, const FrameCamera &rest) {
  return [&live, rest](int k) {
    live.request.camera.focus_distance_m = 1.0f + 0.05f * float(k % 20);
    live.request.camera.look_at = rest.look_at + glm::vec3(0.01f * float(k % 7), 0.0f, 0.0f);
  };
}

TEST_P(FrameAllocations, AFocusPullWithAPanAllocatesNothingFrameAfterFrame) {
  LiveFrames live(GetParam());
  if (!live.available())
    GTEST_SKIP() << "no Vulkan device";
  const FrameCamera rest = live.request.camera;
  live.prepare();
  EXPECT_EQ(live.allocations_in([&] { live.frames(20, pull_and_pan(live, rest)); }), 0u);

  // The count works: a camera gone far beyond the scene's objects from its
  // origin builds the region's world-space part again (influence_region.h).
  EXPECT_GT(live.allocations_in([&] {
    live.frames(1, [&](int) {
      live.request.camera.position = rest.position + glm::vec3(0.0f, 0.0f, 100.0f);
    });
  }),
            0u);
}

TEST_P(FrameAllocations, AFocusPullAllocatesNothingFrameAfterFrame) {
  LiveFrames live(GetParam());
  if (!live.available())
    GTEST_SKIP() << "no Vulkan device";
  const auto pull = [&](int k) {
    live.request.camera.focus_distance_m = 1.0f + 0.05f * float(k % 20);
  };
  live.prepare();
  EXPECT_EQ(live.allocations_in([&] { live.frames(20, pull); }), 0u);
  if (GetParam() == Executor::cpu) { // the frames were moved, not only kept
    EXPECT_GT(live.reprojected, 0u);
  }
}

// Through a lens model (a barrel with its principal point off centre) the
// region's hulls go through the lens and the samples move through it: the
// storage reserved holds them, frame after frame.
TEST_P(FrameAllocations, APullThroughALensModelAllocatesNothingFrameAfterFrame) {
  LiveFrames live(GetParam());
  if (!live.available())
    GTEST_SKIP() << "no Vulkan device";
  live.request.camera.lens_model.k1 = -0.2f;
  live.request.camera.lens_model.k2 = 0.05f;
  live.request.camera.lens_model.principal_point = {0.52f, 0.47f};
  const FrameCamera rest = live.request.camera;
  live.prepare();
  EXPECT_EQ(live.allocations_in([&] { live.frames(20, pull_and_pan(live, rest)); }), 0u);
}

// A frame budget between two whole rays (FrameRequest::extra_rays_per_pixel):
// a held shot's frames after the pilot spend the fraction by noise, and a
// pull's frames, none moved into the next (so each a first frame), at
// their edges and in blocks of their blurred pixels (ray_shares.h).
TEST_P(FrameAllocations, AFractionOfARayAllocatesNothingFrameAfterFrame) {
  LiveFrames live(GetParam());
  if (!live.available())
    GTEST_SKIP() << "no Vulkan device";
  live.request.rays_per_pixel = 1;
  live.request.extra_rays_per_pixel = 0.5f;
  live.request.accumulation.reproject = false;
  live.prepare();
  EXPECT_EQ(live.allocations_in([&] { live.frames(20); }), 0u);
  const auto pull = [&](int k) {
    live.request.camera.focus_distance_m = 0.3f + 0.05f * float(k % 20);
  };
  EXPECT_EQ(live.allocations_in([&] { live.frames(20, pull); }), 0u);
}

// Frames whose pose is not known yet go out as the camera image alone
// (FrameRequest::plate_only), as a run's do until its tracker first finds
// the board, and between them frames that accumulate.
TEST_P(FrameAllocations, PlateOnlyFramesAllocateNothing) {
  LiveFrames live(GetParam());
  if (!live.available())
    GTEST_SKIP() << "no Vulkan device";
  live.prepare();
  EXPECT_EQ(live.allocations_in(
                [&] { live.frames(20, [&](int k) { live.request.plate_only = k % 5 < 2; }); }),
            0u);
}

INSTANTIATE_TEST_SUITE_P(Executors, FrameAllocations,
                         ::testing::Values(Executor::cpu, Executor::gpu),
                         [](const ::testing::TestParamInfo<Executor> &param) {
                           return param.param == Executor::cpu ? "cpu" : "gpu";
                         });

} // namespace
} // namespace camhead::renderer
