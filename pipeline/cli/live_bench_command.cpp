// camhead bench live: the live frame's virtual image as a viewer sees it, as
// error against time (a still shot within 1 s as clean as 49 rays per pixel,
// a focus pull as clean as 9, without ghosting). For each lens state the live
// renderer (a frame renderer as `camhead run` drives it: the CPU reference's
// or, with --executor gpu, the Vulkan tracer's) renders a still shot frame
// after frame at the rays per frame the rig holds at the camera's rate,
// accumulating (frame_history.h), and each frame's composite is measured
// against a converged render of the same camera; so are fresh frames of 1, 9
// and 49 rays per pixel (the paper's settings, in the same run, by the same
// executor), and frames of a focus pull: each state reached by a pull at the
// rig's speed, every frame a new history, which starts with the frames
// before moved through the new focus (accumulation.h, reproject) or, as
// before that, afresh. Error = relative RMSE of the composite over the
// influence region (elsewhere the composite is the camera image, exactly),
// in linear light before the outputs' 8-bit rounding. For the pull frames,
// also the speed-accuracy chart: error against frame time for fresh frames
// and live ones across their rays per pixel, each time a median of three
// measured in the same run.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/geometric.hpp>

#include "camhead/base/progress_line.h"
#include "camhead/base/video_format.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/frame_settings.h"
#include "camhead/renderer/influence_region.h"
#include "camhead/renderer/scene_loader.h"
#include "cli/commands.h"
#include "cli/live_bench.h"
#include "config/data_dir.h"

namespace camhead::cli {
namespace {

namespace fs = std::filesystem;
using namespace renderer;
using namespace live;

// The live frames' renderer; the camera image and the reference are the CPU
// reference's whatever it is.
std::unique_ptr<FrameRenderer> live_renderer(const Scene &scene, const LiveArgs &args) {
  return args.executor == "gpu" ? make_gpu_frame_renderer(scene, args.device)
                                : make_cpu_frame_renderer(scene, args.threads);
}

base::VideoFormat rgb24(const Scene &scene) {
  base::VideoFormat f;
  f.pixel = base::PixelFormat::rgb24;
  f.width = scene.render.width;
  f.height = scene.render.height;
  f.range = base::ColorRange::full;
  return f;
}

FrameCamera camera_at(const Scene &scene, const LensPoint &lens) {
  FrameCamera camera = scene_camera(scene);
  camera.focus_distance_m = lens.focus_m;
  camera.f_number = lens.f_number;
  return camera;
}

// A fresh frame's seed, the same for its rays per pixel wherever it is
// measured: 0x1000 and the number's decimal digits as hex (49: 0x1049).
std::uint32_t uniform_seed(std::uint32_t salt, std::uint32_t rpp) {
  return salt + 0x1000u + (rpp / 10u) * 16u + rpp % 10u;
}

// One lens state's measurements: a renderer, the camera frame it composites
// into (the real proxy as this lens sees it, standing in for the camera),
// the reference and the region.
class Shot {
public:
  Shot(const Scene &scene, const CompiledScene &compiled, const LensPoint &lens,
       const LiveArgs &args)
      : scene_(scene), args_(args), camera_(camera_at(scene, lens)), format_(rgb24(scene)),
        renderer_(live_renderer(scene, args)) {
    // The camera image: the proxy alone through the same lens, 16 rpp.
    Scene real = scene;
    std::erase_if(real.objects, [](const Object &o) { return !o.real; });
    auto real_renderer = make_cpu_frame_renderer(real, args.threads);
    plate_.resize(base::frame_bytes(format_));
    out_.resize(base::frame_bytes(format_));
    FrameRequest plate_request;
    plate_request.camera = camera_;
    plate_request.rays_per_pixel = 16;
    const VideoBuffer plate_target{format_, plate_};
    check(real_renderer->render(plate_request, {}, std::span(&plate_target, 1)), "the plate");

    gpu::FrameParams frame = make_frame_params(scene, camera_);
    set_has_plate(frame, true);
    const InfluenceRegion region = influence_region(compiled, frame);
    for (const PixelRect &r : region.rects)
      for (std::uint32_t y = r.y0; y < r.y1; ++y)
        for (std::uint32_t x = r.x0; x < r.x1; ++x)
          region_pixels_.push_back(std::size_t(y) * std::size_t(scene.render.width) + x);

    base::ProgressLine progress(lens.name + ": reference, " + std::to_string(args.ref_rpp) +
                                " rpp");
    FrameRequest reference;
    reference.camera = camera_;
    reference.rays_per_pixel = std::uint32_t(args.ref_rpp);
    reference.seed = 0x5eedu;
    auto reference_renderer = make_cpu_frame_renderer(scene, args.threads);
    const VideoBuffer target{format_, out_};
    check(reference_renderer->render(reference, {format_, plate_}, std::span(&target, 1)),
          "the reference");
    progress.finish();
    const std::span<const glm::vec4> c = reference_renderer->last_composite();
    reference_.assign(c.begin(), c.end());
    reference_picture_ = out_;
  }

  // The last frame as the outputs got it (RGB, 8 bits), and the reference.
  [[nodiscard]] const std::vector<std::uint8_t> &picture() const { return out_; }
  [[nodiscard]] const std::vector<std::uint8_t> &reference_picture() const {
    return reference_picture_;
  }

  // A fresh frame of `rpp`, nothing accumulated (the live default before).
  double uniform_error(std::uint32_t rpp, std::uint32_t seed) {
    FrameRequest request;
    request.camera = camera_;
    request.rays_per_pixel = rpp;
    request.seed = seed;
    render(request, std::to_string(rpp) + " rpp");
    return error();
  }

  // The live frame: `rpp` more rays while the camera holds still.
  double live_error(double rpp, std::uint32_t seed, std::uint32_t *history) {
    *history = render(live_request(camera_, rpp, seed, true), "a live frame").history_samples;
    return error();
  }

  // The live frame at the end of a pull through `focus_before` (metres, the
  // frames before it, in order), each frame `rpp` rays; with `reproject`,
  // each frame's history starts with the frames before it moved. On a new
  // renderer: the one before would move its own last frames' samples into
  // the pull's first, or go on with its pattern.
  double pull_error(double rpp, std::uint32_t seed, std::span<const float> focus_before,
                    bool reproject, std::uint32_t *history) {
    renderer_ = live_renderer(scene_, args_);
    for (std::size_t k = 0; k < focus_before.size(); ++k) {
      FrameCamera camera = camera_;
      camera.focus_distance_m = focus_before[k];
      (void)render(live_request(camera, rpp, seed + 1 + std::uint32_t(k), reproject),
                   "a pull frame");
    }
    const FrameReport last = render(live_request(camera_, rpp, seed, reproject), "a pull frame");
    *history = last.history_samples;
    last_rays_ =
        last.traced_pixels > 0 ? double(last.camera_rays) / double(last.traced_pixels) : 0.0;
    return error();
  }

  [[nodiscard]] double region_fraction() const {
    return double(region_pixels_.size()) / double(std::size_t(format_.width) * format_.height);
  }

  // For the chart of error against frame time: a frame rendered kTimings
  // times with the same samples (the same error each time).

  // A fresh frame of `rpp`, as uniform_error.
  TimedFrame timed_uniform(std::uint32_t rpp, std::uint32_t seed) {
    std::array<double, kTimings> seconds{};
    TimedFrame t;
    for (double &s : seconds) {
      t.error = uniform_error(rpp, seed);
      s = last_seconds_;
    }
    t.seconds = median(seconds);
    t.rays = rpp;
    return t;
  }

  // The last frame of a pull, as pull_error.
  TimedFrame timed_pull(double rpp, std::uint32_t seed, std::span<const float> focus_before,
                        bool reproject) {
    std::array<double, kTimings> seconds{};
    TimedFrame t;
    for (double &s : seconds) {
      std::uint32_t history = 0;
      t.error = pull_error(rpp, seed, focus_before, reproject, &history);
      s = last_seconds_;
    }
    t.seconds = median(seconds);
    t.rays = last_rays_;
    return t;
  }

private:
  FrameRequest live_request(const FrameCamera &camera, double rpp, std::uint32_t seed,
                            bool reproject) const {
    FrameRequest request;
    request.camera = camera;
    set_mean_rays_per_pixel(request, rpp);
    request.seed = seed;
    request.accumulation.enabled = true;
    request.accumulation.reconstruct = args_.reconstruct > 0.0;
    request.accumulation.reconstruct_strength = args_.reconstruct;
    request.accumulation.reproject = reproject;
    return request;
  }

  static void check(const FrameReport &report, const std::string &what) {
    if (report.status != FrameStatus::ok)
      throw std::runtime_error(what + ": " + report.detail);
  }

  FrameReport render(FrameRequest request, const std::string &what) {
    request.keep_composite = true; // the GPU's, read back for error()
    const VideoBuffer target{format_, out_};
    const FrameReport report = renderer_->render(request, {format_, plate_}, std::span(&target, 1));
    check(report, what);
    // What the frame budget counts of a frame (FrameBudget::measured): the
    // camera frame in, the trace, the outputs out.
    last_seconds_ = report.decode_s + report.trace_s + report.encode_s;
    return report;
  }

  static double median(std::array<double, kTimings> values) {
    std::sort(values.begin(), values.end());
    return values[kTimings / 2];
  }

  // Relative RMSE (compare.py's: RMSE / RMS of the reference) of the last
  // composite over the region.
  double error() const {
    const std::span<const glm::vec4> c = renderer_->last_composite();
    double diff = 0.0, ref = 0.0;
    for (const std::size_t i : region_pixels_)
      for (int k = 0; k < 3; ++k) {
        const double a = reference_[i][k], b = c[i][k];
        diff += (a - b) * (a - b);
        ref += a * a;
      }
    return std::sqrt(diff / ref);
  }

  const Scene &scene_;
  const LiveArgs &args_;
  FrameCamera camera_;
  base::VideoFormat format_;
  std::unique_ptr<FrameRenderer> renderer_;
  std::vector<std::uint8_t> plate_, out_, reference_picture_;
  std::vector<std::size_t> region_pixels_;
  std::vector<glm::vec4> reference_;
  double last_seconds_ = 0.0;
  double last_rays_ = 0.0;
};

int run_live(LiveArgs args) {
  if (!(args.rpp >= 1.0)) { // NaN passes CLI::Range
    std::fprintf(stderr, "bench live: --rpp %g is not a number of rays per pixel\n", args.rpp);
    return 2;
  }
  // In sixteenths of a ray, as the frames take it (set_mean_rays_per_pixel),
  // so that the tables print what was rendered.
  args.rpp = in_ray_steps(args.rpp);
  if (!args.device.empty() && args.executor != "gpu") {
    std::fprintf(stderr,
                 "bench live: --device '%s' picks a Vulkan device for --executor gpu; the "
                 "live frames are the %s executor's\n",
                 args.device.c_str(), args.executor.c_str());
    return 2;
  }
  try {
    const fs::path scene_file =
        args.scene.empty() ? pipeline::data_dir() / "scenes" / "sim_rig.json" : args.scene;
    const Scene scene = load_scene(scene_file);
    const CompiledScene compiled = compile_scene(scene);
    const double frame_s = 1.0 / args.fps;
    // The rig's holds and its pull (make_sim_focus_pull.py): far at f/4,
    // near at f/2, and the scene's own focus.
    const std::vector<LensPoint> still = {{"far 14 m f/4", 14.0f, 4.0f},
                                          {"scene " + fmt(scene.camera.focus_distance_m, "%.1f") +
                                               " m f/" + fmt(scene.camera.f_number, "%.1f"),
                                           scene.camera.focus_distance_m, scene.camera.f_number},
                                          {"near 0.4 m f/2", 0.4f, 2.0f}};
    // The pull: five states even in diopters between the holds; each is
    // reached by kPullFrames frames at the rig's pull's mean speed (its 1.5
    // s from 14 to 0.4 m), from the far side, the far end from the near
    // side (the pull back).
    constexpr float kFarW = 1.0f / 14.0f, kNearW = 1.0f / 0.4f;
    const float pull_speed = (kNearW - kFarW) / float(1.5 * args.fps); // diopters a frame
    constexpr int kPullFrames = 12;
    std::vector<LensPoint> pulling;
    for (int k = 0; k < 5; ++k) {
      const float w = kFarW + (kNearW - kFarW) * float(k) / 4.0f;
      pulling.push_back({"pull " + fmt(1.0 / w, "%.2f") + " m f/2.8", 1.0f / w, 2.8f});
    }
    const auto approach = [&](const LensPoint &lens) {
      std::vector<float> focus;
      const float w = 1.0f / lens.focus_m;
      const bool far_end = &lens == &pulling.front();
      const float step = far_end ? pull_speed : -pull_speed;
      for (int j = kPullFrames; j >= 1; --j)
        focus.push_back(1.0f / std::clamp(w + step * float(j), kFarW, kNearW));
      return focus;
    };

    // Another --seed draws every live and uniform frame's samples anew (the
    // reference's stay), to see how far a figure is the seed's.
    const std::uint32_t salt = args.seed * 0x10000u;
    std::vector<RestCurve> rest, pull;
    for (const bool is_still : {true, false})
      for (const LensPoint &lens : is_still ? still : pulling) {
        Shot shot(scene, compiled, lens, args);
        RestCurve c;
        c.lens = lens;
        c.region = shot.region_fraction();
        c.uniform1 = shot.uniform_error(1, uniform_seed(salt, 1));
        if (!is_still)
          c.pictures.push_back(shot.picture());
        c.uniform9 = shot.uniform_error(9, uniform_seed(salt, 9));
        const std::vector<std::uint8_t> nine = shot.picture();
        c.uniform49 = shot.uniform_error(49, uniform_seed(salt, 49));
        // Still: frame after frame; pulling: the state's frame at the end
        // of the pull, afresh, then with the frames before moved.
        if (is_still) {
          for (int k = 0; k < args.frames; ++k) {
            std::uint32_t samples = 0;
            c.error.push_back(
                shot.live_error(args.rpp, salt + 0x2000u + std::uint32_t(k), &samples));
            c.samples.push_back(samples);
            c.seconds.push_back((k + 1) * frame_s);
          }
        } else {
          const std::vector<float> before = approach(lens);
          c.afresh = shot.pull_error(args.rpp, salt + 0x2000u, before, false, &c.afresh_samples);
          std::uint32_t samples = 0;
          c.error.push_back(shot.pull_error(args.rpp, salt + 0x2000u, before, true, &samples));
          c.samples.push_back(samples);
          c.seconds.push_back(frame_s);
        }
        if (!is_still) {
          c.pictures.push_back(shot.picture());
          c.pictures.push_back(nine);
          c.pictures.push_back(shot.reference_picture());
          base::ProgressLine progress(lens.name + ": error against frame time");
          for (const std::uint32_t rpp : kUniformRays)
            c.uniform.push_back(shot.timed_uniform(rpp, uniform_seed(salt, rpp)));
          const std::vector<float> before = approach(lens);
          for (const double rpp : kLiveRays) {
            c.moved.push_back(shot.timed_pull(rpp, salt + 0x2000u, before, true));
            c.fresh.push_back(shot.timed_pull(rpp, salt + 0x2000u, before, false));
          }
          progress.finish();
        }
        (is_still ? rest : pull).push_back(std::move(c));
      }

    print_tables(args, scene_file, scene, rest, pull);
    write_reports(args, scene, rest, pull);
    return 0;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "bench live: %s\n", e.what());
    return 1;
  }
}

} // namespace

void add_bench_live_command(CLI::App &bench) {
  auto args = std::make_shared<live::LiveArgs>();
  CLI::App *cmd = bench.add_subcommand(
      "live", "The live frame's error against time, as camhead run renders it (the CPU\n"
              "reference, or --executor gpu): for three still lens states (the simulated\n"
              "rig's far and near holds and the scene's own focus) each frame's composite\n"
              "after the lens came to rest, accumulating --rpp rays a frame, and for five\n"
              "states of a focus pull the frame that reaches it after 12 frames of a pull\n"
              "at the rig's speed, its history started with the frames before moved\n"
              "through the new focus, and afresh; each against a --ref-rpp reference of\n"
              "the same camera (the CPU reference's) and against fresh frames of 1, 9 and\n"
              "49 rays per pixel measured in the same run. Error: relative RMSE of the\n"
              "composite over the influence region, linear light. For the pull frames,\n"
              "also their error against frame time: fresh frames of 1 to 49 rpp and live\n"
              "frames of 1 to 4, each frame's time the median of three. Writes\n"
              "DIR/live.csv, DIR/live.png (the error against time), DIR/live_speed.csv,\n"
              "DIR/live_speed.png (the pull frames' error against frame time) and\n"
              "DIR/live_pull.png (the pull frames, cropped). About 5 minutes on 2 cores\n"
              "for the simulated rig.\n"
              "Example:\n"
              "  camhead bench live -o /tmp/live");
  cmd->add_option("--scene", args->scene, "Scene file (default: the simulated rig's)")
      ->check(path_text() & CLI::ExistingFile);
  cmd->add_option("-o,--output", args->out_dir, "Output folder (created if absent)")
      ->capture_default_str()
      ->check(path_text());
  cmd->add_option("--rpp", args->rpp,
                  "Rays per pixel of each live frame, a mean: what the frame budget holds\n"
                  "at the camera's rate (camhead run's status line). A fraction (1.5; in\n"
                  "sixteenths of a ray) goes where a frame shares its rays unevenly (a\n"
                  "first frame's sharp edges)")
      ->check(CLI::Range(1.0, 4096.0))
      ->capture_default_str();
  cmd->add_option("--frames", args->frames, "Still frames after rest")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--fps", args->fps, "The camera's rate, for the time axis")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--ref-rpp", args->ref_rpp, "Rays per pixel of the reference")
      ->check(CLI::Range(2, 1 << 20))
      ->capture_default_str();
  cmd->add_option("--seed", args->seed,
                  "Draws the live and uniform frames' samples anew (not the reference's): a\n"
                  "margin that holds under several seeds is not one seed's luck")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "CPU threads (0 = all cores)")->capture_default_str();
  cmd->add_option("--executor", args->executor,
                  "cpu (the CPU reference) or gpu (the Vulkan tracer, lavapipe included) for\n"
                  "the live and the fresh frames; the reference and the camera image are\n"
                  "the CPU reference's either way. The GPU's history shares no rays by noise\n"
                  "and moves no samples through a new focus (frame_renderer.h)")
      ->check(CLI::IsMember({"cpu", "gpu"}))
      ->capture_default_str();
  cmd->add_option("--device", args->device, "Vulkan device by index or name substring");
  cmd->add_option("--reconstruct", args->reconstruct,
                  "Strength of the reconstruction from neighbours' samples (renderer\n"
                  "defocus_filter.h: sigma = strength sqrt(blur radius) / samples^(1/3)); 0 = off")
      ->check(CLI::Range(0.0, 4.0))
      ->capture_default_str();
  cmd->callback([args] { set_exit_code(run_live(*args)); });
}

} // namespace camhead::cli
