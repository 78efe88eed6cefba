// Whole frames at the paper's settings (method.md section 4: 720 x 576 at 1,
// 25 and 49 rays per pixel; 59 / 12 / 7 fps on a GTX 590) and at 1920 x 1080,
// on the GPU tracer and on the CPU reference as its peer.
//
// A GPU frame is one GpuTracer::render() call ending with the 8-bit display
// image in host memory, as a live frame and `camhead bench` do. Counters,
// per second of wall time: frames (fps) and Grays (10^9 camera rays, width x
// height x rpp per frame); a camera ray also carries its shadow rays and any
// secondary rays (RESULTS.md). Mrays/frame is the frame's camera rays.
#include <string>

#include "bench_cache.h"
#include "benchmarks.h"
#include "camhead/renderer/cpu_tracer.h"

#include <benchmark/benchmark.h>

namespace camhead::bench {
namespace {

struct FrameCase {
  BenchScene scene;
  int width = 0;
  int height = 0;
  int rpp = 0;
};

std::string frame_key(const FrameCase &c) {
  return c.scene.name + "/" + std::to_string(c.width) + "x" + std::to_string(c.height) +
         "/rpp:" + std::to_string(c.rpp);
}

void set_frame_counters(benchmark::State &state, const FrameCase &c) {
  const double rays = double(c.width) * c.height * c.rpp;
  state.counters["frames"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["Grays"] =
      benchmark::Counter(double(state.iterations()) * rays * 1e-9, benchmark::Counter::kIsRate);
  state.counters["Mrays/frame"] = rays * 1e-6;
}

void gpu_frame(benchmark::State &state, const FrameCase &c) {
  BenchCache &cache = BenchCache::get();
  const PreparedScene &prepared = cache.scene(c.scene, c.width, c.height);
  std::string error;
  renderer::GpuTracer *tracer = cache.gpu_with(prepared, error);
  if (tracer == nullptr) {
    state.SkipWithError(("no Vulkan device: " + error).c_str());
    return;
  }
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(prepared.scene, c.rpp);
  const auto layers = renderer::LayerSelection::display_only();
  if (cache.first_use("gpu/" + frame_key(c))) {
    (void)tracer->render(frame, {}, layers);
  }
  for (auto _ : state) {
    const renderer::RenderResult result = tracer->render(frame, {}, layers);
    benchmark::DoNotOptimize(result.display.data());
  }
  set_frame_counters(state, c);
}

void cpu_frame(benchmark::State &state, const FrameCase &c) {
  BenchCache &cache = BenchCache::get();
  const PreparedScene &prepared = cache.scene(c.scene, c.width, c.height);
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(prepared.scene, c.rpp);
  for (auto _ : state) {
    const renderer::RenderResult result = renderer::render_cpu(prepared.compiled, frame);
    benchmark::DoNotOptimize(result.composite.data.data());
  }
  set_frame_counters(state, c);
}

} // namespace

void register_frame_benchmarks() {
  struct Size {
    int width, height;
  };
  const Size sizes[] = {{720, 576}, {1920, 1080}};
  const int rpps[] = {1, 25, 49};
  for (const BenchScene &scene : bench_scenes()) {
    for (const Size size : sizes) {
      for (const int rpp : rpps) {
        const FrameCase c{scene, size.width, size.height, rpp};
        benchmark::RegisterBenchmark(("Frame/gpu/" + frame_key(c)).c_str(), gpu_frame, c)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
        benchmark::RegisterBenchmark(("Frame/cpu/" + frame_key(c)).c_str(), cpu_frame, c)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
    }
  }
}

} // namespace camhead::bench
