// embree_peer: Embree 3 as the CPU ceiling for camhead's ray throughput.
//
// Loads a scene through camhead's loader and compile_scene(), hands the same
// triangles and spheres to Embree, makes exactly the camera rays that
// camhead's thin-lens camera makes (the kernel's own camera_ray(), compiled
// as C++ as the CPU reference does) and traces them, closest hit only, on
// all cores: rtcIntersect1 per ray, rtcIntersect16 packets (4 x 4 pixels,
// one sample) and rtcIntersect1M streams (all samples of a 4 x 4 block).
// With --camhead, camhead's CPU reference and GPU tracer render the same
// frame in the same process, interleaved round by round, so that ratios
// hold on a noisy machine. Prints Markdown rows (bench/run_peers.sh).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "bench_scenes.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/gpu_tracer.h"
#include "embree_rays.h"

namespace camhead::bench {
namespace {

using renderer::cpu::CpuKernel;

// Rays that graze an edge shared by two triangles may hit either in one
// tracer and both or neither in the other (Moeller-Trumbore is not
// watertight); on the bench scenes all sampled rays agree.
constexpr double kMinAgreement = 0.999;

struct Args {
  std::string scene = "ar_basic";
  int width = 720;
  int height = 576;
  int rpp = 1;
  int rounds = 5;
  int threads = 0;
  bool camhead = false;
  std::string device;
  bool header = true;
  std::uint32_t sampler = SAMPLER_CMJ; // camhead's camera-ray sampler (layout.h)
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// ---------------------------------------------------------------- report

struct Row {
  std::string tracer;
  std::string work;
  std::vector<double> rays_per_s;
  std::vector<double> trace_only_rays_per_s; // Embree: ray generation excluded
};

int run(const Args &args) {
  const BenchScene bench_scene = find_bench_scene(args.scene);
  const renderer::Scene scene = load_bench_scene(bench_scene, args.width, args.height);
  const renderer::CompiledScene compiled = renderer::compile_scene(scene);
  renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, args.rpp);
  frame.tracing.z = args.sampler;
  const int threads =
      args.threads > 0 ? args.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  const double rays = double(args.width) * args.height * args.rpp;

  const EmbreeWorld world = make_embree_world(compiled);
  std::vector<renderer::gpu::BvhNode> nodes;
  CpuKernel kernel = renderer::cpu::make_cpu_kernel(compiled, frame, nodes);

  std::unique_ptr<renderer::GpuTracer> gpu;
  if (args.camhead) {
    gpu = std::make_unique<renderer::GpuTracer>(args.device);
    gpu->load(compiled);
  }

  // Every 16th pixel in each direction; every pixel of a small image.
  const int step = args.width * args.height > 100000 ? 16 : 1;
  const double agree = hit_agreement(world.scene.get(), kernel, step);
  bool consistent = agree >= kMinAgreement;
  std::fprintf(stderr,
               "embree_peer: %s (%zu primitives), %dx%d, %d rpp, %d threads; %s, BVH built in "
               "%.0f ms; hit agreement with camhead's closest_hit: %.4f\n",
               bench_scene.name.c_str(), compiled.primitives.size(), args.width, args.height,
               args.rpp, threads, describe_embree(world.device.get()).c_str(), world.build_s * 1e3,
               agree);

  const Mode modes[] = {Mode::single, Mode::packet16, Mode::stream};
  std::vector<Row> rows;
  for (const Mode mode : modes) {
    rows.push_back({std::string("Embree ") + mode_name(mode), "closest hit", {}, {}});
  }
  const std::string camhead_work = bench_scene.primary_only
                                       ? "closest hit + sampling, accumulation, resolve"
                                       : "full shading (shadow and secondary rays)";
  if (args.camhead) {
    rows.push_back({"camhead CPU reference", camhead_work, {}, {}});
    rows.push_back({"camhead GPU (" + gpu->device_name() + ")", camhead_work, {}, {}});
  }
  std::uint64_t hits_first = 0;
  // Round 0 is a warm-up and is not counted.
  for (int round = 0; round <= args.rounds; ++round) {
    for (std::size_t m = 0; m < std::size(modes); ++m) {
      const EmbreeFrame f = embree_frame(world.scene.get(), kernel, modes[m], threads);
      if (round == 0 && m == 0) {
        hits_first = f.hits;
      } else if (f.hits != hits_first) {
        consistent = false;
        std::fprintf(stderr, "embree_peer: %s hit %llu rays, rtcIntersect1 %llu\n",
                     mode_name(modes[m]), (unsigned long long)f.hits,
                     (unsigned long long)hits_first);
      }
      if (round > 0) {
        rows[m].rays_per_s.push_back(rays / f.wall_s);
        rows[m].trace_only_rays_per_s.push_back(rays / (f.trace_s / threads));
      }
    }
    if (args.camhead) {
      const double cpu_s = renderer::render_cpu(compiled, frame).seconds;
      const double gpu_s = gpu->render(frame, {}, renderer::LayerSelection::display_only()).seconds;
      if (round > 0) {
        rows[3].rays_per_s.push_back(rays / cpu_s);
        rows[4].rays_per_s.push_back(rays / gpu_s);
      }
    }
  }

  double best_embree = 0.0;
  for (std::size_t m = 0; m < std::size(modes); ++m) {
    best_embree = std::max(best_embree, median(rows[m].rays_per_s));
  }
  if (args.header) {
    std::printf("| scene | size, rpp | tracer | work per camera ray | M rays/s | M rays/s, "
                "tracing only | / best Embree |\n"
                "|---|---|---|---|---|---|---|\n");
  }
  for (const Row &row : rows) {
    const double r = median(row.rays_per_s);
    char trace_only[32] = "-";
    if (!row.trace_only_rays_per_s.empty()) {
      std::snprintf(trace_only, sizeof trace_only, "%.3g",
                    median(row.trace_only_rays_per_s) * 1e-6);
    }
    std::printf("| %s | %dx%d, %d | %s | %s | %.3g | %s | %.3g |\n", bench_scene.name.c_str(),
                args.width, args.height, args.rpp, row.tracer.c_str(), row.work.c_str(), r * 1e-6,
                trace_only, r / best_embree);
  }
  // Exit status 3: the peers did not trace the same rays against the same
  // scene (the smoke test in bench/CMakeLists.txt checks this).
  return consistent ? 0 : 3;
}

bool parse(int argc, char **argv, Args &args) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg(argv[i]);
    auto value = [&]() -> const char * { return i + 1 < argc ? argv[++i] : ""; };
    if (arg == "--scene") {
      args.scene = value();
    } else if (arg == "--width") {
      args.width = std::atoi(value());
    } else if (arg == "--height") {
      args.height = std::atoi(value());
    } else if (arg == "--rpp") {
      args.rpp = std::atoi(value());
    } else if (arg == "--rounds") {
      args.rounds = std::atoi(value());
    } else if (arg == "--threads") {
      args.threads = std::atoi(value());
    } else if (arg == "--device") {
      args.device = value();
    } else if (arg == "--camhead") {
      args.camhead = true;
    } else if (arg == "--no-header") {
      args.header = false;
    } else if (arg == "--sampler") {
      const std::string_view name = value();
      if (name != "cmj" && name != "sobol")
        return false;
      args.sampler = name == "sobol" ? SAMPLER_SOBOL : SAMPLER_CMJ;
    } else {
      return false;
    }
  }
  return args.width > 0 && args.height > 0 && args.rpp > 0 && args.rounds > 0;
}

} // namespace
} // namespace camhead::bench

int main(int argc, char **argv) {
  camhead::bench::Args args;
  if (!camhead::bench::parse(argc, argv, args)) {
    std::fprintf(stderr,
                 "usage: embree_peer [--scene ar_basic|ar_demo|ar_basic_primary|ar_demo_primary|"
                 "FILE]\n"
                 "                   [--width 720] [--height 576] [--rpp 1] [--rounds 5]\n"
                 "                   [--threads all] [--camhead [--device NAME]] [--no-header]\n"
                 "                   [--sampler cmj|sobol]\n");
    return 2;
  }
  try {
    return camhead::bench::run(args);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "embree_peer: %s\n", e.what());
    return 1;
  }
}
