// camhead render: one still of a scene file, on the GPU or the CPU reference.
#include <cctype>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include "camhead/base/partial_file.h"
#include "camhead/base/progress_line.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/frame_settings.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/image_io.h"
#include "camhead/renderer/influence_region.h"
#include "camhead/renderer/mesh_io.h"
#include "camhead/renderer/scene_loader.h"
#include "cli/commands.h"
#include "run/run_paths.h"

namespace camhead::cli {
namespace {

struct RenderArgs {
  std::string scene;
  std::string output;
  int rpp = 0;
  std::optional<std::uint32_t> seed;
  bool cpu = false;
  bool adaptive = false;
  int threads = 0;
  std::string layer = "composite";
  std::string device;
  bool no_influence_region = false;
};

const renderer::Image &pick_layer(const renderer::RenderResult &r, const std::string &layer) {
  if (layer == "mixed") {
    return r.mixed;
  }
  if (layer == "real") {
    return r.real;
  }
  if (layer == "mask") {
    return r.mask;
  }
  if (layer == "depth") {
    return r.depth;
  }
  return r.composite;
}

// The composite with the pixels outside the influence region at a quarter
// of their brightness: what --layer region shows.
void dim_outside(renderer::Image &image, const renderer::InfluenceRegion &region) {
  std::vector<bool> inside(std::size_t(image.width) * image.height, false);
  for (const renderer::PixelRect &r : region.rects)
    for (std::uint32_t y = r.y0; y < r.y1; ++y)
      for (std::uint32_t x = r.x0; x < r.x1; ++x)
        inside[std::size_t(y) * image.width + x] = true;
  for (std::size_t i = 0; i < inside.size(); ++i)
    if (!inside[i])
      for (int c = 0; c < image.channels; ++c)
        image.data[i * image.channels + c] *= 0.25f;
}

// Refuses an output that could not be written before spending a long render
// on it.
std::optional<std::string> output_problem(const std::filesystem::path &output) {
  std::string ext = output.extension().string();
  for (char &c : ext) {
    c = char(std::tolower(static_cast<unsigned char>(c)));
  }
  if (ext != ".exr" && ext != ".png") {
    return "must end in .exr (linear float) or .png (8-bit sRGB)";
  }
  const std::filesystem::path dir = output.parent_path();
  if (!dir.empty() && !std::filesystem::is_directory(dir)) {
    return "folder " + dir.string() + " does not exist";
  }
  // What writing it will meet (base/partial_file.h), found now rather than
  // after the render: a folder, a device node, a place this user cannot
  // write to.
  if (std::string reason = base::check_replaceable(output); !reason.empty())
    return reason;
  if (::access(dir.empty() ? "." : dir.c_str(), W_OK) != 0)
    return "folder " + (dir.empty() ? std::string(".") : dir.string()) + " is not writable";
  return std::nullopt;
}

int run_render(const RenderArgs &args) {
  using namespace camhead::renderer;
  if (const auto problem = output_problem(args.output)) {
    std::fprintf(stderr, "output %s: %s\n", args.output.c_str(), problem->c_str());
    return 4;
  }
  try {
    Scene scene = load_scene(args.scene);
    // An image written over the scene's own plate or a mesh would destroy it.
    std::vector<pipeline::RunPath> paths = pipeline::scene_inputs(scene);
    paths.push_back({"-o " + args.output, args.output, true, false});
    pipeline::check_run_paths(paths);
    if (args.seed) {
      scene.render.seed = *args.seed;
    }
    const CompiledScene compiled = compile_scene(scene);
    const gpu::FrameParams frame = make_frame_params(scene, args.rpp);
    const int rpp = int(rays_per_pixel(frame));
    // The region leaves the layers other than the composite unmade outside it.
    const bool use_region =
        !args.no_influence_region && (args.layer == "composite" || args.layer == "region");
    const InfluenceRegion region =
        use_region ? influence_region(compiled, frame)
                   : whole_frame_region(image_size(frame).x, image_size(frame).y);
    std::fprintf(stderr,
                 "%s: %dx%d, %d rpp, %zu primitives, %zu lights, %.1f %% of the pixels "
                 "traced%s\n",
                 args.scene.c_str(), scene.render.width, scene.render.height, rpp,
                 compiled.primitives.size(), compiled.lights.size(), 100.0 * region.fraction(),
                 !use_region            ? ""
                 : !scene.plate         ? " (no plate: the composite is the render)"
                 : region.whole_frame() ? " (the virtual objects reach everywhere)"
                                        : " (the influence region)");

    RenderResult result;
    std::string executor;
    if (args.cpu) {
      executor = "CPU reference";
      base::ProgressLine progress("render (CPU)");
      const ProgressFn report = [&](int done, int total) { progress.update(done, total); };
      result = args.adaptive
                   ? render_cpu_adaptive(compiled, frame, {}, report, args.threads, &region)
                   : render_cpu(compiled, frame, report, args.threads, &region);
      progress.finish();
    } else {
      GpuTracer tracer(args.device);
      executor = tracer.device_name();
      base::ProgressLine progress("render (" + executor + ")");
      tracer.load(compiled);
      const ProgressFn report = [&](int done, int total) { progress.update(done, total); };
      result = args.adaptive ? tracer.render_adaptive(frame, {}, report, {}, &region)
                             : tracer.render(frame, report, {}, &region);
      progress.finish();
    }
    if (args.layer == "region")
      dim_outside(result.composite, region);
    write_image(args.output, pick_layer(result, args.layer));
    const double rays_per_second = double(result.camera_rays) / result.seconds;
    std::fprintf(stderr, "%s: %s written; %.3f s on %s, %.1f M camera rays/s (%.1f fps)\n",
                 args.output.c_str(), args.layer.c_str(), result.seconds, executor.c_str(),
                 rays_per_second * 1e-6, 1.0 / result.seconds);
    return 0;
  } catch (const SceneError &e) {
    std::fprintf(stderr, "scene error: %s\n", e.what());
    return 2;
  } catch (const pipeline::RunPathError &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const GpuError &e) {
    std::fprintf(stderr, "Vulkan error: %s\n(--cpu renders with the CPU reference instead)\n",
                 e.what());
    return 3;
  } catch (const ImageError &e) {
    std::fprintf(stderr, "image error: %s\n", e.what());
    return 4;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

} // namespace

void add_render_command(CLI::App &app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App *cmd = app.add_subcommand(
      "render", "Render one still of a scene file (JSON, see scene-format.md).\n"
                "Example: camhead render scenes/ar_demo.json --rpp 49 -o out.png");
  cmd->add_option("scene", args->scene, "Scene file (JSON)")
      ->required()
      ->check(path_text() & CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output,
                  "Output image: .exr (linear float) or .png (8-bit sRGB)")
      ->required()
      ->check(path_text());
  cmd->add_option("--rpp", args->rpp,
                  "Rays per pixel (default: the scene's render.samples). The paper's\n"
                  "live setting is 49; 1024 approaches a converged reference")
      ->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--seed", args->seed, "Sampling seed (default: the scene's render.seed)");
  cmd->add_option("--layer", args->layer,
                  "composite: I_f, the camera image with the virtual objects;\n"
                  "mixed: I_m, real proxy + virtual; real: I_r, real proxy alone;\n"
                  "mask: M, virtual coverage; depth: mean camera-axis depth (m);\n"
                  "region: the composite, darkened outside the influence region (the pixels\n"
                  "the virtual objects, their shadows and reflections can change)")
      ->check(CLI::IsMember({"composite", "mixed", "real", "mask", "depth", "region"}));
  cmd->add_flag("--cpu", args->cpu, "Use the CPU reference tracer instead of Vulkan");
  cmd->add_flag("--adaptive", args->adaptive,
                "Adaptive ray budget: --rpp on average, shared out per pixel by a pilot's\n"
                "variance and circle of confusion (renderer adaptive.h)");
  cmd->add_option("--threads", args->threads, "CPU threads for --cpu (default: all)")
      ->check(CLI::Range(0, 1024));
  cmd->add_flag("--no-influence-region", args->no_influence_region,
                "Trace every pixel. By default a composite traces only where the virtual\n"
                "objects, their shadows and their reflections can change it (the same image,\n"
                "bit for bit); the other layers always trace every pixel");
  cmd->add_option("--device", args->device,
                  "Vulkan device by index or name substring (see camhead devices);\n"
                  "default: the first GPU, else lavapipe");
  cmd->callback([args] { set_exit_code(run_render(*args)); });
}

} // namespace camhead::cli
