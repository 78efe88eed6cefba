// camhead bench chart: error against frame time, per method and budget
// (method.md section 5: "error against a trusted reference is charted against
// frame time").
//
// For each scene: a converged reference from the CPU reference tracer (cached
// in the output folder), a mask of the pixels near depth edges, then every
// method of kMethods at each of its budgets: the median frame time on the GPU
// (bench_command.cpp's approach: repeated frames after warm-up, each from the
// first kernel to the 8-bit display image in host memory, by the device's
// timestamps where it has them) and the relative RMSE of
// its composite against the reference, over all pixels and over the edge
// mask. Writes chart.csv and one chart_<scene>.png per scene.
#include "chart_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/dof_gather.h"
#include "camhead/renderer/frame_settings.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/image_io.h"
#include "camhead/renderer/scene_loader.h"
#include "chart_errors.h"
#include "chart_plot.h"
#include "commands.h"
#include "progress.h"

namespace camhead::cli {
namespace {

using namespace camhead::renderer;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct ChartArgs {
  std::vector<std::string> scenes;
  std::string out_dir = "bench";
  double scale = 1.0;
  int frames = 5;
  int warmup = 2;
  int ref_rpp = 1024;
  int threads = 0;
  std::string device;
  std::vector<std::string> methods; // empty = all
};

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Median of `frames` timed calls after `warmup` untimed ones; `frame` returns
// the seconds of one call.
double median_seconds(const ChartArgs &args, const std::function<double()> &frame) {
  std::vector<double> times;
  for (int i = 0; i < args.warmup + args.frames; ++i) {
    const double s = frame();
    if (i >= args.warmup)
      times.push_back(s);
  }
  return median(times);
}

// A frame's time as the chart counts it: the device's own timestamps where
// it has them (a host clock adds the latency of submitting and waiting,
// which is most of a frame under 3 ms on an H100 and the same for every
// method), else the wall time of the call.
double frame_seconds(const RenderResult &r) {
  return r.timings.device_s > 0.0 ? r.timings.device_s : r.seconds;
}

// ---------------------------------------------------------------- methods

// What a method needs to make frames of one scene.
struct ChartContext {
  const Scene &scene;
  GpuTracer &tracer;
  DofGather &gather;
  const ChartArgs &args;
  std::span<const glm::vec4> plate; // I_c for the gather's composite; empty without
  float max_blur_radius_px = 0.0f;  // of the scene's depth range, for the gather
};

struct Measurement {
  Image composite;
  double frame_s = 0.0;
  double post_s = std::numeric_limits<double>::quiet_NaN(); // image-space pass, part of frame_s
};

struct Method {
  const char *name;         // CSV and legend
  const char *description;  // --help
  std::vector<int> budgets; // rays per pixel
  chart::Rgb color;
  chart::Marker marker;
  Measurement (*run)(ChartContext &, int rpp);
};

// The tracer's frame at `rpp` with camera sampler `sampler`.
Measurement run_traced(ChartContext &c, int rpp, CameraSampler sampler) {
  gpu::FrameParams frame = make_frame_params(c.scene, rpp);
  set_camera_sampler(frame, sampler);
  Measurement m;
  m.frame_s = median_seconds(c.args, [&] {
    return frame_seconds(c.tracer.render(frame, {}, LayerSelection::display_only()));
  });
  m.composite = c.tracer.render(frame).composite;
  return m;
}

// 1. The tracer as it is: stratified jittered pixel and lens samples
//    (method.md section 2).
Measurement run_uniform(ChartContext &c, int rpp) {
  return run_traced(c, rpp, CameraSampler::cmj);
}

// 1b. The same budgets with the low-discrepancy sampler: pixel and aperture
//     jointly from Owen-scrambled Sobol' (sampling.glsl).
Measurement run_sobol(ChartContext &c, int rpp) {
  return run_traced(c, rpp, CameraSampler::sobol);
}

// 2. Image-space depth of field: a pinhole render (aperture radius 0) at
//    `rpp` for antialiasing, blurred by dof_gather.comp. Frame time = the
//    pinhole frame (up to the display image in host memory) + the gather
//    kernel with its input on the device, which is what a frame that ran
//    both on one GPU would take; the host round trip the gather gets its
//    input through here is not counted.
Measurement run_pinhole_gather(ChartContext &c, int rpp) {
  gpu::FrameParams pinhole = make_frame_params(c.scene, rpp);
  set_pinhole(pinhole);
  const gpu::FrameParams lens = make_frame_params(c.scene, rpp);
  const double trace_s = median_seconds(c.args, [&] {
    return frame_seconds(c.tracer.render(pinhole, {}, LayerSelection::display_only()));
  });
  const RenderResult layers = c.tracer.render(pinhole);
  DofGatherSettings settings;
  settings.max_radius_px = c.max_blur_radius_px;
  Measurement m;
  const double gather_s = median_seconds(c.args, [&] {
    DofGatherResult r = c.gather.apply(layers, lens, c.plate, settings);
    m.composite = std::move(r.image.composite);
    return r.device_s > 0.0 ? r.device_s : r.gather_s;
  });
  m.frame_s = trace_s + gather_s;
  m.post_s = gather_s;
  return m;
}

// 3. Adaptive ray budget (renderer adaptive.h): `rpp` rays per pixel on
//    average, a pilot then each pixel's share by its variance and blur, no
//    share over `max_factor` times the mean.
Measurement run_adaptive_capped(ChartContext &c, int rpp, float max_factor) {
  const gpu::FrameParams frame = make_frame_params(c.scene, rpp);
  AdaptiveSampling settings;
  settings.max_factor = max_factor;
  Measurement m;
  m.frame_s = median_seconds(c.args, [&] {
    return frame_seconds(
        c.tracer.render_adaptive(frame, settings, {}, LayerSelection::display_only()));
  });
  m.composite = c.tracer.render_adaptive(frame, settings).composite;
  return m;
}

Measurement run_adaptive(ChartContext &c, int rpp) {
  return run_adaptive_capped(c, rpp, AdaptiveSampling{}.max_factor);
}

// 3b. The same with no share over 4x the mean: on a GPU the second pass
//     lasts as long as its longest invocation, one pixel's whole share
//     (bench/RESULTS.md, "Adaptive on a GPU: the longest share").
Measurement run_adaptive_cap4(ChartContext &c, int rpp) {
  return run_adaptive_capped(c, rpp, 4.0f);
}

// The method table: a new sampler (low-discrepancy, adaptive) is one more
// entry here with its own run function; the chart, CSV and legend follow.
const std::vector<Method> &methods() {
  static const std::vector<Method> table = {
      {"uniform",
       "thin-lens tracer, stratified jittered sampling (method.md 2)",
       {1, 4, 9, 16, 25, 49, 100},
       {31, 119, 180},
       chart::Marker::circle,
       run_uniform},
      {"sobol",
       "thin-lens tracer, Owen-scrambled Sobol' pixel and lens samples (sampling.glsl)",
       {1, 4, 9, 16, 25, 49, 100},
       {255, 127, 14},
       chart::Marker::triangle,
       run_sobol},
      {"pinhole+gather",
       "pinhole render + depth-aware gather blur (dof_gather.comp)",
       {1, 4, 16},
       {214, 39, 40},
       chart::Marker::square,
       run_pinhole_gather},
      {"adaptive",
       "thin-lens tracer, adaptive ray budget per pixel from a pilot (renderer adaptive.h)",
       {4, 9, 16, 25, 49},
       {44, 160, 44},
       chart::Marker::diamond,
       run_adaptive},
      {"adaptive-cap4",
       "adaptive, no pixel over 4x the mean rays (a GPU's longest thread 4x shorter)",
       {4, 9, 16, 25, 49},
       {148, 103, 189},
       chart::Marker::diamond,
       run_adaptive_cap4},
  };
  return table;
}

// ---------------------------------------------------------------- reference

std::string file_hash(const fs::path &path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016zx", std::hash<std::string>{}(bytes.str()));
  return buf;
}

struct Reference {
  Image composite;
  Image pinhole_depth; // 1 channel
  int rpp = 0;
  double check_all = 0.0, check_edges = 0.0; // half the samples, other seed, vs reference
  Image check;                               // half the samples, another seed
  Image cycles; // the Cycles render at this size, if the scene's folder has one
  std::string cycles_file;
  double cycles_all = std::numeric_limits<double>::quiet_NaN();
  double cycles_edges = std::numeric_limits<double>::quiet_NaN();
};

// A CPU reference render's layer, read from `cache` if an earlier run left it.
Image cached_render(const fs::path &cache, const CompiledScene &compiled,
                    const gpu::FrameParams &frame, const ChartArgs &args, const std::string &label,
                    bool depth_layer) {
  if (fs::exists(cache)) {
    std::fprintf(stderr, "%s: cached in %s\n", label.c_str(), cache.string().c_str());
    Image image = read_image(cache);
    if (!depth_layer)
      return image;
    Image single(image.width, image.height, 1);
    for (std::size_t i = 0; i < single.pixel_count(); ++i)
      single.data[i] = image.data[i * 3];
    return single;
  }
  ProgressLine progress(label);
  RenderResult r = render_cpu(
      compiled, frame, [&](int done, int total) { progress.update(done, total); }, args.threads);
  progress.finish();
  Image image = depth_layer ? std::move(r.depth) : std::move(r.composite);
  write_image(cache, image);
  return image;
}

// ---------------------------------------------------------------- one scene

struct Row {
  std::string method;
  int rpp = 0;
  double frame_ms = std::numeric_limits<double>::quiet_NaN();
  double all = 0.0, edges = 0.0;
  double post_ms = std::numeric_limits<double>::quiet_NaN();
};

struct SceneRun {
  std::string name;
  int width = 0, height = 0;
  double edge_fraction = 0.0;
  int edge_radius = 0;
  Reference reference;
  std::vector<Row> rows;
};

Scene load_scaled(const std::string &file, double scale) {
  Scene scene = load_scene(file);
  const int k = int(std::lround(1.0 / scale));
  scene.render.width /= k;
  scene.render.height /= k;
  if (scene.plate) {
    if (scene.plate->width % k != 0 || scene.plate->height % k != 0)
      throw std::runtime_error(file + ": plate size " + std::to_string(scene.plate->width) + "x" +
                               std::to_string(scene.plate->height) + " is not divisible by 1/" +
                               std::to_string(k) + " (--scale)");
    scene.plate = box_downsample(*scene.plate, k);
  }
  return scene;
}

std::vector<glm::vec4> plate_vec4(const Scene &scene) {
  std::vector<glm::vec4> out;
  if (!scene.plate)
    return out;
  for (std::size_t i = 0; i < scene.plate->pixel_count(); ++i) {
    const float *p = &scene.plate->data[i * 3];
    out.emplace_back(p[0], p[1], p[2], 0.0f);
  }
  return out;
}

Reference make_reference(const std::string &file, const Scene &scene, const CompiledScene &compiled,
                         const ChartArgs &args, const fs::path &cache_dir) {
  const std::string stem = fs::path(file).stem().string();
  const std::string key = stem + "_" + file_hash(file) + "_" + std::to_string(scene.render.width) +
                          "x" + std::to_string(scene.render.height);
  Reference ref;
  ref.rpp = args.ref_rpp;
  const gpu::FrameParams frame = make_frame_params(scene, args.ref_rpp);
  ref.composite = cached_render(
      cache_dir / (key + "_ref" + std::to_string(args.ref_rpp) + ".exr"), compiled, frame, args,
      "reference " + stem + " " + std::to_string(args.ref_rpp) + " rpp (CPU)", false);
  // The convergence check: half the samples with another seed. Independent
  // noise, so the reference's own error is about this / sqrt(3).
  gpu::FrameParams half = make_frame_params(scene, std::max(1, args.ref_rpp / 2));
  set_seed(half, seed(half) + 1);
  ref.check = cached_render(
      cache_dir / (key + "_check" + std::to_string(args.ref_rpp / 2) + ".exr"), compiled, half,
      args, "check " + stem + " " + std::to_string(args.ref_rpp / 2) + " rpp (CPU)", false);
  gpu::FrameParams pinhole = make_frame_params(scene, 16);
  set_pinhole(pinhole);
  ref.pinhole_depth = cached_render(cache_dir / (key + "_pinhole_depth.exr"), compiled, pinhole,
                                    args, "edge mask " + stem + " (CPU)", true);
  // Cycles, where the shared reference folder has the matching layer.
  for (const char *suffix : {"_composite.exr", "_1024.exr"}) {
    const fs::path cycles = fs::path(file).parent_path() / (stem + suffix);
    if (!fs::exists(cycles))
      continue;
    Image image = read_image(cycles);
    const int k = image.width / std::max(1, scene.render.width);
    if (k >= 1 && image.width == k * scene.render.width &&
        image.height == k * scene.render.height) {
      ref.cycles_file = cycles.filename().string();
      ref.cycles = box_downsample(image, k);
    }
    break;
  }
  return ref;
}

std::string fmt(double v, const char *format = "%.6g") {
  if (std::isnan(v))
    return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void write_chart(const SceneRun &run, const std::vector<const Method *> &chosen,
                 const std::string &device, const fs::path &png) {
  std::vector<chart::Panel> panels(2);
  panels[0].title = "all pixels";
  panels[1].title = "depth edges (" + fmt(run.edge_fraction * 100.0, "%.0f") + "% of pixels, " +
                    std::to_string(run.edge_radius) + " px)";
  for (chart::Panel &panel : panels) {
    panel.x_label = "frame time (ms)";
    panel.y_label = "relative RMSE";
  }
  for (const Method *method : chosen) {
    for (std::size_t p = 0; p < panels.size(); ++p) {
      chart::Series s;
      s.name = method->name;
      s.color = method->color;
      s.marker = method->marker;
      for (const Row &row : run.rows) {
        if (row.method != method->name)
          continue;
        s.x.push_back(row.frame_ms);
        s.y.push_back(p == 0 ? row.all : row.edges);
        s.labels.push_back(std::to_string(row.rpp));
      }
      panels[p].series.push_back(std::move(s));
    }
  }
  const std::string title = run.name + " " + std::to_string(run.width) + "x" +
                            std::to_string(run.height) + ", " + device + ", reference " +
                            std::to_string(run.reference.rpp) + " rpp, points labelled with rpp";
  const chart::Canvas canvas = chart::plot_log_log(title, panels, 640, 480);
  Image image(canvas.width, canvas.height, 3);
  for (std::size_t i = 0; i < canvas.rgb.size(); ++i)
    image.data[i] = srgb_to_linear(canvas.rgb[i] / 255.0f);
  write_image(png, image);
}

int run_chart(const ChartArgs &args) {
  try {
    const int k = int(std::lround(1.0 / args.scale));
    if (!(args.scale > 0.0) || std::abs(k * args.scale - 1.0) > 1e-6)
      throw std::runtime_error("--scale " + fmt(args.scale) +
                               " must be 1/k for a whole k (1, 0.5, 0.25, ...)");
    std::vector<const Method *> chosen;
    for (const Method &m : methods())
      if (args.methods.empty() ||
          std::find(args.methods.begin(), args.methods.end(), m.name) != args.methods.end())
        chosen.push_back(&m);
    for (const std::string &name : args.methods)
      if (std::none_of(methods().begin(), methods().end(),
                       [&](const Method &m) { return name == m.name; }))
        throw std::runtime_error("--methods: no method '" + name + "'");

    const fs::path out_dir = args.out_dir;
    const fs::path cache_dir = out_dir / "chart_cache";
    std::error_code ec;
    fs::create_directories(cache_dir, ec);
    if (ec)
      throw std::runtime_error("cannot create " + cache_dir.string() + ": " + ec.message());

    GpuTracer tracer(args.device);
    DofGather gather(tracer.device_name());
    const std::string device = tracer.device_name();
    std::fprintf(stderr, "device %s; %d timed frames after %d warm-up frames per setting\n",
                 device.c_str(), args.frames, args.warmup);

    // Camera rays still to trace, for the ETA (the gather is cheap beside them).
    double rays_total = 0.0;
    std::vector<Scene> scenes;
    for (const std::string &file : args.scenes) {
      scenes.push_back(load_scaled(file, args.scale));
      const double pixels = double(scenes.back().render.width) * scenes.back().render.height;
      for (const Method *m : chosen)
        for (int rpp : m->budgets)
          rays_total += pixels * rpp * (args.warmup + args.frames + 1);
    }
    double rays_done = 0.0, timed_s = 0.0;

    std::vector<SceneRun> runs;
    for (std::size_t si = 0; si < scenes.size(); ++si) {
      const std::string &file = args.scenes[si];
      const Scene &scene = scenes[si];
      SceneRun run;
      run.name = fs::path(file).stem().string();
      run.width = scene.render.width;
      run.height = scene.render.height;
      const CompiledScene compiled = compile_scene(scene);
      run.reference = make_reference(file, scene, compiled, args, cache_dir);

      const gpu::FrameParams lens = make_frame_params(scene);
      float max_radius = 0.5f;
      for (float z : run.reference.pinhole_depth.data)
        max_radius = std::max(max_radius, coc_radius_px(lens, z));
      run.edge_radius = int(std::ceil(max_radius));
      const std::vector<std::uint8_t> mask =
          depth_edge_mask(run.reference.pinhole_depth, run.edge_radius);
      run.edge_fraction = double(std::count(mask.begin(), mask.end(), 1)) / double(mask.size());

      Reference &ref = run.reference;
      ref.check_all = relative_rmse(ref.composite, ref.check);
      ref.check_edges = relative_rmse(ref.composite, ref.check, mask);
      if (!ref.cycles_file.empty()) {
        ref.cycles_all = relative_rmse(ref.cycles, ref.composite);
        ref.cycles_edges = relative_rmse(ref.cycles, ref.composite, mask);
      }
      std::fprintf(stderr,
                   "%s %dx%d: reference %d rpp; %d vs %d rpp rel. RMSE %.2e (edges %.2e); edge "
                   "mask %.1f%% of pixels (radius %d px)",
                   run.name.c_str(), run.width, run.height, ref.rpp, args.ref_rpp / 2, args.ref_rpp,
                   ref.check_all, ref.check_edges, run.edge_fraction * 100.0, run.edge_radius);
      if (!run.reference.cycles_file.empty())
        std::fprintf(stderr, "; vs Cycles %s rel. RMSE %.2e (edges %.2e)", ref.cycles_file.c_str(),
                     ref.cycles_all, ref.cycles_edges);
      std::fprintf(stderr, "\n");

      tracer.load(compiled);
      const std::vector<glm::vec4> plate = plate_vec4(scene);
      ChartContext context{scene, tracer, gather, args, plate, max_radius};
      for (const Method *method : chosen)
        for (int rpp : method->budgets) {
          const Clock::time_point start = Clock::now();
          Measurement m = method->run(context, rpp);
          timed_s += std::chrono::duration<double>(Clock::now() - start).count();
          rays_done += double(run.width) * run.height * rpp * (args.warmup + args.frames + 1);
          Row row{method->name,
                  rpp,
                  m.frame_s * 1e3,
                  relative_rmse(run.reference.composite, m.composite),
                  relative_rmse(run.reference.composite, m.composite, mask),
                  m.post_s * 1e3};
          const double left = rays_done > 0 ? timed_s * (rays_total - rays_done) / rays_done : 0;
          std::fprintf(stderr,
                       "%s %s %3d rpp: %9.2f ms/frame%s, rel. RMSE %.4f (edges %.4f)  [%.0f s, "
                       "about %.0f s left]\n",
                       run.name.c_str(), method->name, rpp, row.frame_ms,
                       std::isnan(row.post_ms)
                           ? ""
                           : (" (image-space pass " + fmt(row.post_ms, "%.3f") + " ms)").c_str(),
                       row.all, row.edges, timed_s, left);
          run.rows.push_back(row);
        }
      runs.push_back(std::move(run));
      const fs::path png = out_dir / ("chart_" + runs.back().name + ".png");
      write_chart(runs.back(), chosen, device, png);
      std::printf("wrote %s\n", png.string().c_str());
    }

    const fs::path csv_path = out_dir / "chart.csv";
    std::ofstream csv(csv_path);
    if (!csv)
      throw std::runtime_error("cannot write " + csv_path.string());
    const std::vector<std::string> header = {
        "scene",    "width",    "height",         "device",          "method",         "rpp",
        "frame_ms", "rel_rmse", "rel_rmse_edges", "edge_pixels_pct", "edge_radius_px", "post_ms",
        "note"};
    csv << chart::csv_row(header) << "\n";
    for (const SceneRun &run : runs) {
      const auto emit = [&](const std::string &method, int rpp, double ms, double all, double edges,
                            double post_ms, const std::string &note) {
        const std::vector<std::string> fields = {run.name,
                                                 std::to_string(run.width),
                                                 std::to_string(run.height),
                                                 device,
                                                 method,
                                                 std::to_string(rpp),
                                                 fmt(ms, "%.4f"),
                                                 fmt(all),
                                                 fmt(edges),
                                                 fmt(run.edge_fraction * 100.0, "%.2f"),
                                                 std::to_string(run.edge_radius),
                                                 fmt(post_ms, "%.4f"),
                                                 note};
        csv << chart::csv_row(fields) << "\n";
      };
      for (const Row &row : run.rows)
        emit(row.method, row.rpp, row.frame_ms, row.all, row.edges, row.post_ms,
             "vs CPU reference " + std::to_string(run.reference.rpp) + " rpp");
      emit("reference_check", args.ref_rpp / 2, std::numeric_limits<double>::quiet_NaN(),
           run.reference.check_all, run.reference.check_edges,
           std::numeric_limits<double>::quiet_NaN(),
           "CPU reference " + std::to_string(args.ref_rpp / 2) + " rpp (seed+1) vs " +
               std::to_string(run.reference.rpp) + " rpp");
      if (!run.reference.cycles_file.empty())
        emit("cycles", run.reference.rpp, std::numeric_limits<double>::quiet_NaN(),
             run.reference.cycles_all, run.reference.cycles_edges,
             std::numeric_limits<double>::quiet_NaN(),
             "CPU reference vs Cycles " + run.reference.cycles_file + " (Cycles as reference)");
    }
    std::printf("wrote %s\n", csv_path.string().c_str());
    return 0;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "bench chart: %s\n", e.what());
    return 1;
  }
}

} // namespace

void add_bench_chart_command(CLI::App &bench) {
  auto args = std::make_shared<ChartArgs>();
  std::string method_list;
  for (const Method &m : methods()) {
    std::string budgets;
    for (int rpp : m.budgets)
      budgets += (budgets.empty() ? "" : ", ") + std::to_string(rpp);
    method_list += "\n  " + std::string(m.name) + ": " + m.description + "; rpp " + budgets;
  }
  CLI::App *cmd = bench.add_subcommand(
      "chart",
      "Speed versus accuracy: renders each scene with each method at each budget,\n"
      "times the frames on the GPU (median after warm-up; by the device's timestamps\n"
      "where it has them) and measures the relative RMSE of the composite against a\n"
      "converged CPU reference, over all pixels and near depth edges. Writes\n"
      "DIR/chart.csv and DIR/chart_<scene>.png (log-log).\n"
      "The references are cached in DIR/chart_cache, so a rerun only re-times.\n"
      "Methods:" +
          method_list +
          "\nExamples (2 CPU cores, lavapipe: the first takes over half an hour, the\n"
          "second a few minutes):\n"
          "  camhead bench chart tests/assets/reference/ar_basic.json --scale 0.5 -o bench\n"
          "  camhead bench chart tests/assets/reference/ar_basic.json --scale 0.25 \\\n"
          "      --methods uniform,adaptive --frames 3 --warmup 1 -o /tmp/chart");
  cmd->add_option("scenes", args->scenes, "Scene files")
      ->required()
      ->check(path_text() & CLI::ExistingFile);
  cmd->add_option("-o,--output", args->out_dir, "Output folder (created if absent)")
      ->capture_default_str()
      ->check(path_text());
  cmd->add_option("--scale", args->scale,
                  "Render at this fraction of the scene's size: 1, 0.5, 0.25, ... (the plate\n"
                  "is box-filtered to match; the blur in pixels scales with it)")
      ->capture_default_str();
  cmd->add_option("--frames", args->frames, "Timed frames per setting (median)")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--warmup", args->warmup, "Untimed frames first")
      ->check(CLI::Range(0, 10000))
      ->capture_default_str();
  cmd->add_option("--ref-rpp", args->ref_rpp,
                  "Rays per pixel of the CPU reference (a second render at half of it with\n"
                  "another seed shows how converged it is)")
      ->check(CLI::Range(2, 1 << 20))
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "CPU reference threads (0 = all cores)")
      ->capture_default_str();
  cmd->add_option("--methods", args->methods, "Only these methods (comma-separated)")
      ->delimiter(',');
  cmd->add_option("--device", args->device, "Vulkan device by index or name substring");
  cmd->callback([args] { set_exit_code(run_chart(*args)); });
}

} // namespace camhead::cli
