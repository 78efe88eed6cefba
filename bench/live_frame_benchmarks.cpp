// A live frame of the simulated rig as `camhead run` renders it: the
// FrameRenderer of scenes/sim_rig.json at 720x576, a YUYV camera frame in and
// a YUYV composite out, 1 ray per pixel (where the rig's frame budget sits on
// two cores; far_fresh 2), the lens pulling focus from frame to frame. This is the work
// the run loop's render thread does, without the simulated camera, the lens
// thread and the outputs beside it, so that a change to the kernel, the
// region or the conversions can be measured in seconds rather than in a
// 90-second run whose first minute fills the camera's cache.
//
// Counters: frames (fps) and traced (the influence region's share of the
// pixels, the mean over the frames).
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bench_scenes.h"
#include "camhead/base/video_format.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/gpu_tracer.h"

#include <benchmark/benchmark.h>

namespace camhead::bench {
namespace {

constexpr int kWidth = 720;
constexpr int kHeight = 576;
// The rig's focus pull (scenes/lenses/make_sim_focus_pull.py: 14 m to 0.4 m
// at a still iris, f/2.8 here) in as many steps as frames of a second, then
// back.
constexpr int kLensStates = 25;

renderer::Scene sim_rig_scene() {
  const BenchScene rig{"sim_rig", source_dir() / "scenes" / "sim_rig.json"};
  return load_bench_scene(rig, kWidth, kHeight);
}

// A camera frame with the detail of a real one: a smooth ramp under a fine
// texture, every code value in range.
std::vector<std::uint8_t> camera_frame(const base::VideoFormat &format) {
  std::vector<std::uint8_t> bytes(base::frame_bytes(format));
  for (int y = 0; y < format.height; ++y)
    for (int x = 0; x < format.width; x += 2) {
      std::uint8_t *pair = &bytes[base::row_bytes(format) * std::size_t(y) + std::size_t(x) * 2];
      pair[0] = std::uint8_t(16 + (x + y) % 200 + (x * 7 % 20));
      pair[1] = std::uint8_t(128 + (y % 64) - 32);
      pair[2] = std::uint8_t(16 + (x + 1 + y) % 200 + (x * 11 % 20));
      pair[3] = std::uint8_t(128 + (x % 64) - 32);
    }
  return bytes;
}

// How the frames are made: each afresh (the live path before issue 24); as
// camhead run makes them, accumulating and reconstructed (on the CPU
// reference with the shares by noise; on the GPU every pixel alike), during
// the pull (each frame starts a new history, with the samples of the frames
// before moved through the new focus: accumulation.h, reproject; the CPU
// reference's only), the same without them (pull_afresh), and with the lens
// still, reconstructed and not (still_raw: what the reconstruction costs),
// and held so long that the history has all it may take (still_capped: 8
// samples a pixel at most, as a locked-off shot's 256 after about 10 s;
// from about the 8th frame on, few rays or none a frame); and a new history
// every frame at the near end of the pull, as a moving camera's frames are,
// reconstructed and not (near_fresh, near_fresh_raw: where the
// reconstruction costs the most, its blur circles 20 pixels wide); and a
// new history every frame focused far, at the 2 rays a pixel that the rig's
// budget gives such frames (far_fresh: where the first frame gives its
// sharp pixels' rays by their neighbours' spread, ray_shares.h).
enum class Method {
  fresh,
  pull,
  pull_afresh,
  still,
  still_raw,
  still_capped,
  near_fresh,
  near_fresh_raw,
  far_fresh
};

std::uint32_t rays_per_pixel(Method method) {
  return method == Method::far_fresh ? 2u : 1u;
}

void live_frame(benchmark::State &state, bool gpu, bool region, Method method) {
  const renderer::Scene scene = sim_rig_scene();
  std::unique_ptr<renderer::FrameRenderer> frames;
  try {
    frames =
        gpu ? renderer::make_gpu_frame_renderer(scene) : renderer::make_cpu_frame_renderer(scene);
  } catch (const renderer::GpuError &e) {
    state.SkipWithError((std::string("no Vulkan device: ") + e.what()).c_str());
    return;
  }
  base::VideoFormat format;
  format.pixel = base::PixelFormat::yuyv;
  format.width = kWidth;
  format.height = kHeight;
  const std::vector<std::uint8_t> plate = camera_frame(format);
  std::vector<std::uint8_t> out(base::frame_bytes(format));
  const renderer::VideoBuffer outputs[] = {{format, out}};

  renderer::FrameRequest request;
  request.camera = renderer::scene_camera(scene);
  request.rays_per_pixel = rays_per_pixel(method);
  request.influence_region = region;
  const bool near = method == Method::near_fresh || method == Method::near_fresh_raw;
  const bool far = method == Method::far_fresh;
  request.accumulation.enabled = method != Method::fresh;
  request.accumulation.reproject = method != Method::pull_afresh && !near && !far;
  request.accumulation.reconstruct =
      method != Method::still_raw && method != Method::near_fresh_raw;
  if (method == Method::still_capped)
    request.accumulation.max_samples = 8;
  request.camera.f_number = 2.8f;
  std::uint64_t frame = 0;
  double traced = 0.0;
  for (auto _ : state) {
    // Equal steps of 1 / distance (the way a focus scale runs), one a frame.
    const bool still =
        method == Method::still || method == Method::still_raw || method == Method::still_capped;
    const int step = still ? 0 : int(frame % (2 * kLensStates - 2));
    const double t =
        double(step < kLensStates ? step : 2 * kLensStates - 2 - step) / double(kLensStates - 1);
    request.camera.focus_distance_m = float(1.0 / (1.0 / 14.0 + t * (1.0 / 0.4 - 1.0 / 14.0)));
    if (near) // 0.40 and 0.41 m in turn: a blur change far past the tolerance
      request.camera.focus_distance_m = frame % 2 == 0 ? 0.40f : 0.41f;
    if (far) // 14 and 10 m in turn: the same
      request.camera.focus_distance_m = frame % 2 == 0 ? 14.0f : 10.0f;
    request.seed = std::uint32_t(++frame * 2654435761u) | 1u;
    const renderer::FrameReport report = frames->render(request, {format, plate}, outputs);
    if (report.status != renderer::FrameStatus::ok) {
      state.SkipWithError(report.detail.c_str());
      return;
    }
    traced += double(report.traced_pixels) / double(report.frame_pixels);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["frames"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["traced"] = traced / double(state.iterations());
}

} // namespace

void register_live_frame_benchmarks() {
  for (const bool gpu : {false, true})
    for (const bool region : {true, false})
      for (const Method method :
           {Method::fresh, Method::pull, Method::pull_afresh, Method::still, Method::still_raw,
            Method::still_capped, Method::near_fresh, Method::near_fresh_raw, Method::far_fresh}) {
        if (method != Method::fresh && !region)
          continue; // a history is kept over the region
        if (method == Method::pull_afresh && gpu)
          continue; // the GPU executor does not reproject
        const char *name = method == Method::fresh          ? "fresh"
                           : method == Method::pull         ? "live_pull"
                           : method == Method::pull_afresh  ? "live_pull_afresh"
                           : method == Method::still        ? "live_still"
                           : method == Method::still_raw    ? "live_still_raw"
                           : method == Method::still_capped ? "live_still_capped"
                           : method == Method::near_fresh   ? "live_near_fresh"
                           : method == Method::far_fresh    ? "live_far_fresh"
                                                            : "live_near_fresh_raw";
        benchmark::RegisterBenchmark(
            (std::string("LiveFrame/") + (gpu ? "gpu" : "cpu") +
             "/sim_rig/720x576/rpp:" + std::to_string(rays_per_pixel(method)) + "/" +
             (region ? "region" : "every_pixel") + "/" + name)
                .c_str(),
            [gpu, region, method](benchmark::State &state) {
              live_frame(state, gpu, region, method);
            })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime()
            ->MinTime(2.0);
      }
}

} // namespace camhead::bench
