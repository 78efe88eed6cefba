// camhead bench: frame rate of the GPU tracer at the paper's settings.
//
// Kan and Kaufmann (2012) report 59, 12 and 7 fps at 720 x 576 for 1, 25 and
// 49 rays per pixel on a GTX 590 (method.md section 4). This command measures
// the same table on whatever device it is given: the median frame time over
// repeated frames after warm-up, each frame the whole render() call (upload
// of the frame parameters, tracing, compositing and read-back of the 8-bit
// display image a live frame shows; --all-layers reads back the float layers
// too), and where that time went. --adaptive times the adaptive ray budget
// (renderer adaptive.h) at the same mean rays per pixel.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/frame_budget.h"
#include "camhead/renderer/frame_settings.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/influence_region.h"
#include "camhead/renderer/scene_loader.h"
#include "chart/chart_command.h"
#include "cli/commands.h"

namespace camhead::cli {
namespace {

struct BenchArgs {
  std::string scene = "scenes/ar_demo.json";
  std::vector<int> rpp{1, 25, 49};
  int width = 720;
  int height = 576;
  int frames = 9;
  int warmup = 2;
  std::string device;
  bool cpu_peer = false;
  bool all_layers = false;
  bool adaptive = false;
  renderer::AdaptiveSampling adaptive_settings; // --adaptive-cap sets max_factor
  bool skip_empty = false;
  double frame_ms = 0.0;      // > 0: follow this frame-time target instead of --rpp
  bool region = false;        // compare the influence region with every pixel
  bool every_feature = false; // the trace kernel with every feature (set_kernel_specialization)
};

std::string sampling_name(const BenchArgs &args) {
  if (!args.adaptive)
    return "uniform";
  char cap[32];
  std::snprintf(cap, sizeof cap, "%g", double(args.adaptive_settings.max_factor));
  return std::string("adaptive (rpp = mean rays per pixel, shares capped at ") + cap + "x it)";
}

double paper_fps(int rpp) {
  switch (rpp) {
  case 1:
    return 59.0;
  case 25:
    return 12.0;
  case 49:
    return 7.0;
  default:
    return 0.0;
  }
}

std::string fmt_ms(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", seconds * 1e3);
  return text;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Median wall time of `frames` calls after `warmup` untimed ones, and the
// median of each phase (each phase's own median, so they need not add up).
struct FrameMedians {
  double total_s = 0.0;
  renderer::FrameTimings phases;
};

template <typename RenderFn> FrameMedians median_frame(const BenchArgs &args, RenderFn render) {
  std::vector<double> total, device, allocation, submit, unpack, submissions;
  for (int i = 0; i < args.warmup + args.frames; ++i) {
    const renderer::RenderResult result = render();
    if (i >= args.warmup) {
      total.push_back(result.seconds);
      device.push_back(result.timings.device_s);
      allocation.push_back(result.timings.allocation_s);
      submit.push_back(result.timings.submit_s);
      unpack.push_back(result.timings.unpack_s);
      submissions.push_back(result.timings.submissions);
    }
  }
  return {median(total),
          {.device_s = median(device),
           .allocation_s = median(allocation),
           .submit_s = median(submit),
           .unpack_s = median(unpack),
           .submissions = int(median(submissions))}};
}

// --frame-ms: every frame's rays per pixel from FrameBudget, which learns
// from the frames' device times; prints each frame and a summary.
int run_frame_target(const BenchArgs &args, renderer::GpuTracer &tracer,
                     const renderer::Scene &scene) {
  using namespace camhead::renderer;
  FrameBudget budget(FrameBudgetSettings{.target_s = args.frame_ms * 1e-3});
  std::printf("frame-time target %.2f ms, %s sampling, %d frames\n\n", args.frame_ms,
              args.adaptive ? "adaptive" : "uniform", args.warmup + args.frames);
  std::printf("| frame | rpp | frame ms (device) |\n|-------|-----|-------------------|\n");
  std::vector<double> times, rpps;
  int late = 0;
  for (int i = 0; i < args.warmup + args.frames; ++i) {
    const std::uint32_t rpp = budget.rpp();
    gpu::FrameParams frame = make_frame_params(scene, int(rpp));
    set_skip_empty_pixels(frame, args.skip_empty);
    const RenderResult r = args.adaptive ? tracer.render_adaptive(frame, args.adaptive_settings, {},
                                                                  LayerSelection::display_only())
                                         : tracer.render(frame, {}, LayerSelection::display_only());
    const double seconds = r.timings.device_s > 0.0 ? r.timings.device_s : r.seconds;
    budget.measured(rpp, seconds);
    std::printf("| %5d | %3u | %17.2f |%s\n", i, rpp, seconds * 1e3,
                i < args.warmup ? " (warm-up)" : "");
    if (i >= args.warmup) {
      times.push_back(seconds);
      rpps.push_back(rpp);
      late += seconds > args.frame_ms * 1e-3 ? 1 : 0;
    }
  }
  std::printf("\nafter warm-up: median %.0f rpp, median frame %.2f ms, %d of %d frames over the "
              "target\n",
              median(rpps), median(times) * 1e3, late, args.frames);
  return 0;
}

// --influence-region: each rpp traced over every pixel and over the
// influence region only (the same composite), on the GPU tracer and, with
// --cpu-peer, the CPU reference, in one process.
int run_region_bench(const BenchArgs &args, renderer::GpuTracer &tracer,
                     const renderer::Scene &scene, const renderer::CompiledScene &compiled) {
  using namespace camhead::renderer;
  const LayerSelection layers =
      args.all_layers ? LayerSelection::all() : LayerSelection::display_only();
  std::printf("median of %d frames after %d warm-up frames; sampling: %s\n\n", args.frames,
              args.warmup, sampling_name(args).c_str());
  std::printf("| rpp | pixels traced | GPU every pixel ms | GPU region ms | GPU speed-up |%s\n",
              args.cpu_peer ? " CPU every pixel ms | CPU region ms | CPU speed-up |" : "");
  std::printf("|-----|---------------|--------------------|---------------|--------------|%s\n",
              args.cpu_peer ? "--------------------|---------------|--------------|" : "");
  for (const int rpp : args.rpp) {
    const gpu::FrameParams frame = make_frame_params(scene, rpp);
    const InfluenceRegion region = influence_region(compiled, frame);
    const auto gpu = [&](const InfluenceRegion *r) {
      return median_frame(args,
                          [&] {
                            return args.adaptive ? tracer.render_adaptive(
                                                       frame, args.adaptive_settings, {}, layers, r)
                                                 : tracer.render(frame, {}, layers, r);
                          })
          .total_s;
    };
    const double gpu_full = gpu(nullptr), gpu_region = gpu(&region);
    std::printf("| %3d | %12.1f%% | %18.2f | %13.2f | %11.2fx |", rpp, 100.0 * region.fraction(),
                gpu_full * 1e3, gpu_region * 1e3, gpu_full / gpu_region);
    if (args.cpu_peer) {
      const auto cpu = [&](const InfluenceRegion *r) {
        return median_frame(args,
                            [&] {
                              return args.adaptive
                                         ? render_cpu_adaptive(compiled, frame,
                                                               args.adaptive_settings, {}, 0, r)
                                         : render_cpu(compiled, frame, {}, 0, r);
                            })
            .total_s;
      };
      const double cpu_full = cpu(nullptr), cpu_region = cpu(&region);
      std::printf(" %18.2f | %13.2f | %11.2fx |", cpu_full * 1e3, cpu_region * 1e3,
                  cpu_full / cpu_region);
    }
    std::printf("\n");
    std::fflush(stdout);
  }
  return 0;
}

int run_bench(const BenchArgs &args) {
  using namespace camhead::renderer;
  try {
    Scene scene = load_scene(args.scene);
    if (args.region &&
        (!scene.plate || scene.plate->width != args.width || scene.plate->height != args.height)) {
      // The region needs a plate (without one the composite is I_m, every
      // pixel); what it holds costs nothing.
      scene.plate = Image(args.width, args.height, 3);
      std::fill(scene.plate->data.begin(), scene.plate->data.end(), 0.18f);
    }
    if (scene.plate && (scene.plate->width != args.width || scene.plate->height != args.height)) {
      scene.plate.reset(); // the plate only costs one read per pixel
    }
    scene.render.width = args.width;
    scene.render.height = args.height;
    GpuTracer tracer(args.device);
    tracer.set_kernel_specialization(!args.every_feature);
    const CompiledScene compiled = compile_scene(scene);
    tracer.load(compiled);
    std::printf("scene %s, %dx%d, device %s, trace kernel %s\n", args.scene.c_str(), args.width,
                args.height, tracer.device_name().c_str(),
                args.every_feature ? "with every feature" : "for the scene's features");
    if (args.frame_ms > 0.0)
      return run_frame_target(args, tracer, scene);
    if (args.region)
      return run_region_bench(args, tracer, scene, compiled);
    std::printf("median of %d frames after %d warm-up frames; read back: %s; sampling: %s\n\n",
                args.frames, args.warmup, args.all_layers ? "all layers" : "8-bit display image",
                sampling_name(args).c_str());
    std::printf("| rpp | camera rays/frame | frame ms (median) | fps   | M camera rays/s | "
                "paper fps (GTX 590) |%s\n",
                args.cpu_peer ? " CPU reference ms | GPU speed / CPU |" : "");
    std::printf("|-----|-------------------|-------------------|-------|-----------------|"
                "---------------------|%s\n",
                args.cpu_peer ? "------------------|-----------------|" : "");
    const LayerSelection layers =
        args.all_layers ? LayerSelection::all() : LayerSelection::display_only();
    std::vector<FrameTimings> breakdown;
    for (int rpp : args.rpp) {
      gpu::FrameParams frame = make_frame_params(scene, rpp);
      set_skip_empty_pixels(frame, args.skip_empty);
      const FrameMedians gpu = median_frame(args, [&] {
        return args.adaptive ? tracer.render_adaptive(frame, args.adaptive_settings, {}, layers)
                             : tracer.render(frame, {}, layers);
      });
      breakdown.push_back(gpu.phases);
      const double frame_s = gpu.total_s;
      const double rays = double(args.width) * args.height * rpp;
      const double paper = paper_fps(rpp);
      std::printf("| %3d | %15.1f M | %17.2f | %5.1f | %15.1f | %19s |", rpp, rays * 1e-6,
                  frame_s * 1e3, 1.0 / frame_s, rays / frame_s * 1e-6,
                  paper > 0 ? std::to_string(int(paper)).c_str() : "-");
      if (args.cpu_peer) {
        // The same kernel on the same frame, compiled as C++: a peer in the
        // same process, so the ratio holds even on a noisy machine.
        const double cpu =
            median_frame(args, [&] {
              return args.adaptive ? render_cpu_adaptive(compiled, frame, args.adaptive_settings)
                                   : render_cpu(compiled, frame);
            }).total_s;
        std::printf(" %16.2f | %15.2f |", cpu * 1e3, cpu / frame_s);
      }
      std::printf("\n");
      std::fflush(stdout);
    }
    std::printf("\nWhere the GPU frame goes (medians, ms; device: timestamps from the first "
                "kernel to the last copy to host memory, 0 without timestamps):\n\n"
                "| rpp | on the device | adaptive allocation (part of it) | submit to last "
                "fence | unpack on host | submissions |\n"
                "|-----|---------------|----------------------------------|--------------------"
                "--|----------------|-------------|\n");
    for (std::size_t i = 0; i < breakdown.size(); ++i)
      std::printf("| %3d | %13.3f | %32s | %20.3f | %14.3f | %11d |\n", args.rpp[i],
                  breakdown[i].device_s * 1e3,
                  args.adaptive ? fmt_ms(breakdown[i].allocation_s).c_str() : "-",
                  breakdown[i].submit_s * 1e3, breakdown[i].unpack_s * 1e3,
                  breakdown[i].submissions);
    return 0;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "bench: %s\n", e.what());
    return 1;
  }
}

} // namespace

void add_bench_command(CLI::App &app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App *cmd = app.add_subcommand(
      "bench", "Frame rate and camera-ray throughput of the GPU tracer at the paper's\n"
               "settings (720x576; 1, 25, 49 rays per pixel). Prints a Markdown table.");
  cmd->add_option("--scene", args->scene, "Scene file")
      ->check(path_text() & CLI::ExistingFile)
      ->capture_default_str();
  cmd->add_option("--rpp", args->rpp, "Rays per pixel to measure")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--width", args->width, "Image width")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--height", args->height, "Image height")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--frames", args->frames, "Timed frames per setting")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--warmup", args->warmup, "Untimed frames first")
      ->check(CLI::Range(0, 10000))
      ->capture_default_str();
  cmd->add_flag("--all-layers", args->all_layers,
                "Read back every float layer too, not only the 8-bit image a live frame\n"
                "shows");
  CLI::Option *adaptive =
      cmd->add_flag("--adaptive", args->adaptive,
                    "Adaptive ray budget per pixel (a pilot, then shares by variance and blur) at\n"
                    "the same mean rays per pixel");
  cmd->add_option("--adaptive-cap", args->adaptive_settings.max_factor,
                  "With --adaptive: no pixel gets more than this many times the mean rays\n"
                  "per pixel (on a GPU the largest share is the second pass's longest thread)")
      ->check(CLI::Range(1.0f, 1024.0f))
      ->needs(adaptive)
      ->capture_default_str();
  cmd->add_option("--frame-ms", args->frame_ms,
                  "Follow a frame-time target instead of --rpp: each frame's rays per pixel\n"
                  "from the device time of the frames before (renderer frame_budget.h)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--skip-empty-pixels", args->skip_empty,
                "Trace one sample where no ray of a pixel can meet the scene (always on in\n"
                "the CPU reference; on the GPU a measurement, see bench/RESULTS.md)");
  cmd->add_option("--device", args->device, "Vulkan device by index or name substring");
  cmd->add_flag("--every-kernel-feature", args->every_feature,
                "Build the trace kernel with every primitive, material, light and sampler,\n"
                "not only those of the scene and frame: the same image; measures what\n"
                "building the kernel for the scene saves");
  cmd->add_flag("--influence-region", args->region,
                "Time each rpp over every pixel and over the influence region alone (where\n"
                "the virtual objects, their shadows and reflections can change the frame)");
  cmd->add_flag("--cpu-peer", args->cpu_peer,
                "Also time the CPU reference on the same frames and print the ratio");
  add_bench_chart_command(*cmd);
  add_bench_live_command(*cmd);
  // `bench chart ...` and `bench live ...` run alone.
  cmd->callback([args, cmd] {
    if (!cmd->got_subcommand("chart") && !cmd->got_subcommand("live"))
      set_exit_code(run_bench(*args));
  });
}

} // namespace camhead::cli
