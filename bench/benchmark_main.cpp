// camhead_benchmarks: Google Benchmark suite of the tracers (bench/RESULTS.md,
// "Benchmark suite and Embree as the CPU ceiling", has the figures).
//
// Without --benchmark_filter only the quick cases run: 720 x 576 at 1 rpp
// and the micro-benchmarks (about a minute on lavapipe with two cores). The
// paper's whole table is opt-in, e.g.
//   camhead_benchmarks --benchmark_filter='Frame/gpu/ar_basic/720x576'
//   camhead_benchmarks --benchmark_filter='Frame/.*/1920x1080'
//   camhead_benchmarks --benchmark_filter=.            (everything; hours on lavapipe)
// Without --benchmark_repetitions each case runs 3 times and the mean,
// median and spread are shown. --camhead_device=NAME|INDEX picks the Vulkan
// device as GpuTracer does; CAMHEAD_SOURCE_DIR in the environment moves the
// scene folders from where the build found them.
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "bench_cache.h"
#include "benchmarks.h"

#include <benchmark/benchmark.h>

namespace {

constexpr const char *kDefaultFilter = "--benchmark_filter=^Frame/.*/720x576/rpp:1/|^Micro/";

bool has_flag(const std::vector<char *> &args, std::string_view flag) {
  for (const char *arg : args) {
    if (std::string_view(arg).substr(0, flag.size()) == flag) {
      return true;
    }
  }
  return false;
}

} // namespace

int main(int argc, char **argv) {
  using namespace camhead::bench;
  std::vector<char *> args;
  constexpr std::string_view device_flag = "--camhead_device=";
  for (int i = 0; i < argc; ++i) {
    const std::string_view arg(argv[i]);
    if (arg.substr(0, device_flag.size()) == device_flag) {
      BenchCache::get().set_device(std::string(arg.substr(device_flag.size())));
    } else {
      args.push_back(argv[i]);
    }
  }
  std::string filter = kDefaultFilter, repetitions = "--benchmark_repetitions=3",
              aggregates = "--benchmark_display_aggregates_only=true";
  if (!has_flag(args, "--benchmark_filter")) {
    args.push_back(filter.data());
  }
  if (!has_flag(args, "--benchmark_repetitions")) {
    args.push_back(repetitions.data());
    if (!has_flag(args, "--benchmark_display_aggregates_only") &&
        !has_flag(args, "--benchmark_report_aggregates_only")) {
      args.push_back(aggregates.data());
    }
  }
  int count = int(args.size());
  args.push_back(nullptr);
  benchmark::Initialize(&count, args.data());
  if (benchmark::ReportUnrecognizedArguments(count, args.data())) {
    return 1;
  }

  std::string error;
  const camhead::renderer::GpuTracer *gpu = BenchCache::get().gpu(error);
  benchmark::AddCustomContext("vulkan_device", gpu ? gpu->device_name() : "none: " + error);
  register_frame_benchmarks();
  register_live_frame_benchmarks();
  register_micro_benchmarks();
  benchmark::RunSpecifiedBenchmarks();
  BenchCache::get().release_gpu();
  benchmark::Shutdown();
  return 0;
}
