// The parts of a frame's set-up and the smallest units of tracing work:
// compiling a scene, building the BVH of the bunny scene, a frame's
// influence region (by a builder made for the frame, as every frame did
// before issue 24, and by one kept from frame to frame), and one small
// batch of camera rays on each executor (a 64 x 64 frame at 1 rpp, 4096
// rays: on the GPU mostly the fixed cost of a frame, on one CPU thread the
// kernel's own speed).
#include <string>
#include <vector>

#include "bench_cache.h"
#include "benchmarks.h"
#include "camhead/renderer/bvh.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/frame_settings.h"
#include "camhead/renderer/influence_region.h"

#include <benchmark/benchmark.h>

namespace camhead::bench {
namespace {

void compile_scene_bench(benchmark::State &state, const BenchScene &scene) {
  const renderer::Scene loaded = load_bench_scene(scene, 720, 576);
  std::size_t primitives = 0;
  for (auto _ : state) {
    const renderer::CompiledScene compiled = renderer::compile_scene(loaded);
    primitives = compiled.primitives.size();
    benchmark::DoNotOptimize(compiled.nodes.data());
  }
  state.counters["primitives"] = double(primitives);
}

// The BVH alone over the compiled scene's primitives (the bunny is 69,666
// of ar_demo's 69,682).
void build_bvh_bench(benchmark::State &state, const BenchScene &scene) {
  const PreparedScene &prepared = BenchCache::get().scene(scene, 720, 576);
  const std::vector<renderer::gpu::Primitive> &primitives = prepared.compiled.primitives;
  renderer::BvhStats stats;
  for (auto _ : state) {
    renderer::Bvh bvh = renderer::build_bvh(primitives);
    stats = bvh.stats;
    benchmark::DoNotOptimize(bvh.nodes.data());
  }
  state.counters["primitives"] = double(primitives.size());
  state.counters["Mprims"] = benchmark::Counter(
      double(state.iterations()) * double(primitives.size()) * 1e-6, benchmark::Counter::kIsRate);
  state.counters["nodes"] = stats.node_count;
  state.counters["sah_cost"] = stats.sah_cost;
}

// A 720x576 frame's region with a plate, its focus stepping from frame to
// frame as in a pull, so that nothing is the same twice.
void influence_region_bench(benchmark::State &state, const BenchScene &scene, bool kept) {
  const PreparedScene &prepared = BenchCache::get().scene(scene, 720, 576);
  std::vector<renderer::gpu::FrameParams> pull;
  renderer::FrameCamera camera = renderer::scene_camera(prepared.scene);
  const float focus = camera.focus_distance_m;
  for (int step = 0; step < 20; ++step) {
    camera.focus_distance_m = focus * (0.5f + 0.05f * float(step));
    pull.push_back(renderer::make_frame_params(prepared.scene, camera, 1));
    // A plate: the composite is the camera image outside the region.
    renderer::set_has_plate(pull.back(), true);
  }
  renderer::InfluenceRegionBuilder builder(prepared.compiled);
  double fraction = 0.0;
  std::size_t step = 0;
  for (auto _ : state) {
    const renderer::gpu::FrameParams &frame = pull[step++ % pull.size()];
    fraction += kept ? builder.build(frame).fraction()
                     : renderer::influence_region(prepared.compiled, frame).fraction();
  }
  state.counters["traced"] = fraction / double(state.iterations());
}

constexpr int kBatchSide = 64;

void set_batch_counters(benchmark::State &state) {
  state.counters["Mrays"] = benchmark::Counter(
      double(state.iterations()) * kBatchSide * kBatchSide * 1e-6, benchmark::Counter::kIsRate);
}

void gpu_batch_bench(benchmark::State &state, const BenchScene &scene) {
  BenchCache &cache = BenchCache::get();
  const PreparedScene &prepared = cache.scene(scene, kBatchSide, kBatchSide);
  std::string error;
  renderer::GpuTracer *tracer = cache.gpu_with(prepared, error);
  if (tracer == nullptr) {
    state.SkipWithError(("no Vulkan device: " + error).c_str());
    return;
  }
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(prepared.scene, 1);
  const auto layers = renderer::LayerSelection::display_only();
  (void)tracer->render(frame, {}, layers);
  for (auto _ : state) {
    const renderer::RenderResult result = tracer->render(frame, {}, layers);
    benchmark::DoNotOptimize(result.display.data());
  }
  set_batch_counters(state);
}

void cpu_batch_bench(benchmark::State &state, const BenchScene &scene) {
  const PreparedScene &prepared = BenchCache::get().scene(scene, kBatchSide, kBatchSide);
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(prepared.scene, 1);
  for (auto _ : state) {
    const renderer::RenderResult result = renderer::render_cpu(prepared.compiled, frame, {}, 1);
    benchmark::DoNotOptimize(result.composite.data.data());
  }
  set_batch_counters(state);
}

} // namespace

void register_micro_benchmarks() {
  const std::string batch = std::to_string(kBatchSide) + "x" + std::to_string(kBatchSide);
  for (const std::string name : {"ar_basic", "ar_demo"}) {
    const BenchScene scene = find_bench_scene(name);
    benchmark::RegisterBenchmark(("Micro/compile_scene/" + name).c_str(), compile_scene_bench,
                                 scene)
        ->Unit(benchmark::kMillisecond);
    for (const bool kept : {false, true})
      benchmark::RegisterBenchmark(
          ("Micro/influence_region/" + name + "/720x576/" + (kept ? "kept" : "once")).c_str(),
          influence_region_bench, scene, kept)
          ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Micro/gpu_batch/" + name + "/" + batch + "/rpp:1").c_str(),
                                 gpu_batch_bench, scene)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(
        ("Micro/cpu_batch/" + name + "/" + batch + "/rpp:1/threads:1").c_str(), cpu_batch_bench,
        scene)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  benchmark::RegisterBenchmark("Micro/build_bvh/ar_demo", build_bvh_bench,
                               find_bench_scene("ar_demo"))
      ->Unit(benchmark::kMillisecond);
}

} // namespace camhead::bench
