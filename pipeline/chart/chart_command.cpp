// camhead bench chart: error against frame time, per method and budget
// (method.md section 5: "error against a trusted reference is charted against
// frame time").
//
// For each scene: a converged reference from the CPU reference tracer (cached
// in the output folder), a mask of the pixels near depth edges, then every
// method of kMethods at each of its budgets: the median frame time on the GPU
// (cli/bench_command.cpp's approach: repeated frames after warm-up, each from the
// first kernel to the 8-bit display image in host memory, by the device's
// timestamps where it has them) and the relative RMSE of
// its composite against the reference, over all pixels and over the edge
// mask. Writes chart.csv and one chart_<scene>.png per scene.
#include "chart/chart_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/base/progress_line.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/dof_gather.h"
#include "camhead/renderer/frame_settings.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/image_io.h"
#include "camhead/renderer/scene_loader.h"
#include "chart/chart_errors.h"
#include "chart/chart_methods.h"
#include "chart/chart_plot.h"
#include "chart/chart_png.h"
#include "cli/commands.h"

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
  base::ProgressLine progress(label);
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

void write_chart(const SceneRun &run, const std::vector<const chart::Method *> &chosen,
                 const std::string &device, const fs::path &png) {
  std::vector<chart::Panel> panels(2);
  panels[0].title = "all pixels";
  panels[1].title = "depth edges (" + fmt(run.edge_fraction * 100.0, "%.0f") + "% of pixels, " +
                    std::to_string(run.edge_radius) + " px)";
  for (chart::Panel &panel : panels) {
    panel.x_label = "frame time (ms)";
    panel.y_label = "relative RMSE";
  }
  for (const chart::Method *method : chosen) {
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
  chart::write_png(png, canvas);
}

int run_chart(const ChartArgs &args) {
  try {
    const int k = int(std::lround(1.0 / args.scale));
    if (!(args.scale > 0.0) || std::abs(k * args.scale - 1.0) > 1e-6)
      throw std::runtime_error("--scale " + fmt(args.scale) +
                               " must be 1/k for a whole k (1, 0.5, 0.25, ...)");
    std::vector<const chart::Method *> chosen;
    for (const chart::Method &m : chart::methods())
      if (args.methods.empty() ||
          std::find(args.methods.begin(), args.methods.end(), m.name) != args.methods.end())
        chosen.push_back(&m);
    for (const std::string &name : args.methods)
      if (std::none_of(chart::methods().begin(), chart::methods().end(),
                       [&](const chart::Method &m) { return name == m.name; }))
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
      for (const chart::Method *m : chosen)
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
      chart::Context context{
          scene, tracer, gather, {.frames = args.frames, .warmup = args.warmup}, plate, max_radius};
      for (const chart::Method *method : chosen)
        for (int rpp : method->budgets) {
          const Clock::time_point start = Clock::now();
          chart::Measurement m = method->run(context, rpp);
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
  for (const chart::Method &m : chart::methods()) {
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
