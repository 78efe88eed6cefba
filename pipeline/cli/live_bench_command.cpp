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
#include <fstream>
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
#include "chart/chart_plot.h"
#include "chart/chart_png.h"
#include "cli/commands.h"
#include "config/data_dir.h"

namespace camhead::cli {
namespace {

namespace fs = std::filesystem;
using namespace renderer;

struct LiveArgs {
  fs::path scene;
  fs::path out_dir = "bench";
  int ref_rpp = 1024;
  double rpp = 1.0; // rays per pixel of a live frame, a mean
  int frames = 50;
  double fps = 25.0;
  int threads = 0;
  double reconstruct = 1.0; // the filter's strength; 0: off
  std::uint32_t seed = 0;   // 0: the figures in bench/RESULTS.md
  std::string executor = "cpu";
  std::string device; // the Vulkan device, for the GPU executor
};

// Rays per pixel as a person writes them: 2, 1.5.
std::string rays_text(double rpp) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", rpp);
  return text;
}

// The live frames' renderer; the camera image and the reference are the CPU
// reference's whatever it is.
std::unique_ptr<FrameRenderer> live_renderer(const Scene &scene, const LiveArgs &args) {
  return args.executor == "gpu" ? make_gpu_frame_renderer(scene, args.device)
                                : make_cpu_frame_renderer(scene, args.threads);
}

// A lens state of the rig (scenes/lenses/make_sim_focus_pull.py's holds).
struct LensPoint {
  std::string name;
  float focus_m;
  float f_number;
};

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

  // For the chart of error against frame time: a method's error and the
  // median of kTimings frame times, its frame rendered kTimings times with
  // the same samples (the same error each time).
  struct Timed {
    double error = 0.0;
    double seconds = 0.0;
    double rays = 0.0; // a pixel of the region, as traced (a pull frame of
                       // moved samples spends no fraction of a ray)
  };
  static constexpr int kTimings = 3;

  // A fresh frame of `rpp`, as uniform_error.
  Timed timed_uniform(std::uint32_t rpp, std::uint32_t seed) {
    std::array<double, kTimings> seconds{};
    Timed t;
    for (double &s : seconds) {
      t.error = uniform_error(rpp, seed);
      s = last_seconds_;
    }
    t.seconds = median(seconds);
    t.rays = rpp;
    return t;
  }

  // The last frame of a pull, as pull_error.
  Timed timed_pull(double rpp, std::uint32_t seed, std::span<const float> focus_before,
                   bool reproject) {
    std::array<double, kTimings> seconds{};
    Timed t;
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

struct RestCurve {
  LensPoint lens;
  double region = 0.0;
  double uniform1 = 0.0, uniform9 = 0.0, uniform49 = 0.0;
  std::vector<double> seconds, error;
  std::vector<std::uint32_t> samples;
  // Pull frames: the live frame afresh (no samples moved from the frames
  // before) and its samples held.
  double afresh = 0.0;
  std::uint32_t afresh_samples = 0;
  // Pull frames: 1 rpp, the live frame, 9 rpp, the reference (RGB, 8 bits).
  std::vector<std::vector<std::uint8_t>> pictures;
  // Pull frames: error and frame time of fresh frames (kUniformRays) and of
  // live frames with the frames before moved and afresh (kLiveRays).
  std::vector<Shot::Timed> uniform, moved, fresh;
};

// The rays per pixel of the chart of error against frame time: fresh frames
// as before, and live frames across the frame budget's range on two cores
// (1 to 2) and above it.
constexpr std::array<std::uint32_t, 6> kUniformRays = {1, 2, 4, 9, 16, 49};
constexpr std::array<double, 4> kLiveRays = {1.0, 1.5, 2.0, 4.0};

std::string fmt(double v, const char *f = "%.4f") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// A fresh frame's seed, the same for its rays per pixel wherever it is
// measured: 0x1000 and the number's decimal digits as hex (49: 0x1049).
std::uint32_t uniform_seed(std::uint32_t salt, std::uint32_t rpp) {
  return salt + 0x1000u + (rpp / 10u) * 16u + rpp % 10u;
}

// The frame time of a fresh frame as accurate as `error`, in ms: log-log
// between the two fresh frames about it (their error falls as a power of
// their time); beyond those measured, "< " the quickest's or "> " the
// slowest's.
std::string fresh_ms_for(std::span<const Shot::Timed> fresh, double error) {
  if (error >= fresh.front().error)
    return "< " + fmt(1e3 * fresh.front().seconds, "%.0f");
  for (std::size_t k = 0; k + 1 < fresh.size(); ++k) {
    const Shot::Timed &a = fresh[k], &b = fresh[k + 1];
    if (error >= b.error && a.error > b.error) {
      const double f = std::log(a.error / error) / std::log(a.error / b.error);
      return fmt(1e3 * a.seconds * std::pow(b.seconds / a.seconds, f), "%.0f");
    }
  }
  return "> " + fmt(1e3 * fresh.back().seconds, "%.0f");
}

void write_canvas(const fs::path &png, const chart::Canvas &canvas) {
  chart::write_png(png, canvas);
  std::printf("wrote %s\n", png.string().c_str());
}

// The first frame (1-based) whose error is at most `target`, or 0.
std::size_t frames_to(const RestCurve &c, double target) {
  for (std::size_t k = 0; k < c.error.size(); ++k)
    if (c.error[k] <= target)
      return k + 1;
  return 0;
}

void write_outputs(const LiveArgs &args, const std::vector<RestCurve> &rest,
                   const std::vector<RestCurve> &pull) {
  fs::create_directories(args.out_dir);
  const fs::path csv_path = args.out_dir / "live.csv";
  std::ofstream csv(csv_path);
  if (!csv)
    throw std::runtime_error("cannot write " + csv_path.string());
  csv << "shot,lens,frame,seconds,history_samples,error,uniform_1,uniform_9,uniform_49\n";
  const auto row = [&](const char *shot, const RestCurve &c, std::size_t k, std::uint32_t samples,
                       double error) {
    csv << shot << "," << c.lens.name << "," << k + 1 << "," << fmt(c.seconds[k]) << "," << samples
        << "," << fmt(error, "%.6g") << "," << fmt(c.uniform1, "%.6g") << ","
        << fmt(c.uniform9, "%.6g") << "," << fmt(c.uniform49, "%.6g") << "\n";
  };
  for (const RestCurve &c : rest)
    for (std::size_t k = 0; k < c.error.size(); ++k)
      row("still", c, k, c.samples[k], c.error[k]);
  for (const RestCurve &c : pull) {
    row("pull_afresh", c, 0, c.afresh_samples, c.afresh);
    row("pull", c, 0, c.samples[0], c.error[0]);
  }
  std::printf("wrote %s\n", csv_path.string().c_str());

  std::vector<chart::Panel> panels;
  for (const RestCurve &c : rest) {
    chart::Panel panel;
    panel.title = c.lens.name;
    panel.x_label = "seconds since the lens came to rest";
    panel.y_label = "rel. RMSE over the region";
    chart::Series live{"live, " + rays_text(args.rpp) + " rpp a frame, accumulated",
                       {30, 90, 200},
                       chart::Marker::circle,
                       c.seconds,
                       c.error,
                       {}};
    const double x0 = c.seconds.front(), x1 = c.seconds.back();
    chart::Series u9{"uniform 9 rpp", {200, 120, 30},           chart::Marker::square,
                     {x0, x1},        {c.uniform9, c.uniform9}, {}};
    chart::Series u49{"uniform 49 rpp",           {30, 150, 60},
                      chart::Marker::diamond,     {x0, x1},
                      {c.uniform49, c.uniform49}, {}};
    panel.series = {live, u9, u49};
    panels.push_back(std::move(panel));
  }
  const chart::Canvas canvas = chart::plot_log_log("camhead run on the " + args.executor +
                                                       ", still shots: error against time",
                                                   panels, 520, 420);
  write_canvas(args.out_dir / "live.png", canvas);
}

// The pull frames' error against frame time, as a table: each live frame's
// error and time, and the time of a fresh frame as accurate (interpolated
// between the fresh frames measured), so that the live frame's gain is a
// ratio of two times measured in the same run.
void print_speed(const LiveArgs &args, const std::vector<RestCurve> &pull) {
  std::printf("\nError against frame time (the render call: camera frame in, trace, outputs "
              "out; medians of %d), the %s executor:\n\n| pull frame | fresh 1 / 2 / 4 / 9 / "
              "16 / 49 rpp: ms | live, frames before moved, 1 / 1.5 / 2 / 4 rpp: error at ms "
              "(a fresh frame as accurate: ms) |\n|---|---|---|\n",
              Shot::kTimings, args.executor.c_str());
  for (const RestCurve &c : pull) {
    std::string fresh, live;
    for (const Shot::Timed &t : c.uniform)
      fresh += (fresh.empty() ? "" : " / ") + fmt(1e3 * t.seconds, "%.1f");
    for (const Shot::Timed &t : c.moved) {
      live += (live.empty() ? "" : ", ") + fmt(t.error) + " at " + fmt(1e3 * t.seconds, "%.1f") +
              " (" + fresh_ms_for(c.uniform, t.error) + ")";
    }
    std::printf("| %s | %s | %s |\n", c.lens.name.c_str(), fresh.c_str(), live.c_str());
  }
  std::printf("\n(A pull frame of moved samples traces whole rays: 1.5 rpp traces 1, but in "
              "the pull's first frame.%s)\n",
              args.executor == "gpu" ? " The GPU's times include reading the composite back "
                                       "for the error, which camhead run's frames do not; its "
                                       "frames trace whole rays and move no samples."
                                     : "");
}

// DIR/live_speed.csv and DIR/live_speed.png: the pull frames' error against
// frame time, each method a curve of rays per pixel, the camera's frame
// time a vertical line.
void write_speed(const LiveArgs &args, const std::vector<RestCurve> &pull) {
  const fs::path csv_path = args.out_dir / "live_speed.csv";
  std::ofstream csv(csv_path);
  if (!csv)
    throw std::runtime_error("cannot write " + csv_path.string());
  // rpp: what the frame was given; traced_rpp: what it traced (a pull frame
  // of moved samples spends no fraction of a ray).
  csv << "frame,method,rpp,traced_rpp,frame_ms,error\n";
  for (const RestCurve &c : pull) {
    const auto rows = [&](const char *method, std::span<const Shot::Timed> points,
                          const auto &rays) {
      for (std::size_t k = 0; k < points.size(); ++k)
        csv << c.lens.name << "," << method << "," << rays_text(double(rays[k])) << ","
            << fmt(points[k].rays, "%.4g") << "," << fmt(1e3 * points[k].seconds, "%.3f") << ","
            << fmt(points[k].error, "%.6g") << "\n";
    };
    rows("fresh", c.uniform, kUniformRays);
    rows("live_moved", c.moved, kLiveRays);
    rows("live_afresh", c.fresh, kLiveRays);
  }
  std::printf("wrote %s\n", csv_path.string().c_str());

  std::vector<chart::Panel> panels;
  for (const RestCurve &c : pull) {
    chart::Panel panel;
    panel.title = c.lens.name;
    panel.x_label = "ms a frame";
    panel.y_label = "rel. RMSE over the region";
    // Each point labelled with the rays a pixel it traced.
    const auto series = [](std::string name, chart::Rgb color, chart::Marker marker,
                           std::span<const Shot::Timed> points) {
      chart::Series s{std::move(name), color, marker, {}, {}, {}};
      for (const Shot::Timed &p : points) {
        s.x.push_back(1e3 * p.seconds);
        s.y.push_back(p.error);
        s.labels.push_back(fmt(p.rays, "%.2g"));
      }
      return s;
    };
    panel.series = {
        series("fresh frames (rays a pixel)", {200, 120, 30}, chart::Marker::square, c.uniform),
        series("live, the frames before moved", {30, 90, 200}, chart::Marker::circle, c.moved),
        series("live, afresh", {120, 120, 120}, chart::Marker::triangle, c.fresh)};
    double lo = 1.0, hi = 0.0;
    for (const chart::Series &s : panel.series)
      for (const double y : s.y) {
        lo = std::min(lo, y);
        hi = std::max(hi, y);
      }
    const double frame_ms = 1e3 / args.fps;
    panel.series.push_back({"the camera's frame",
                            {200, 40, 40},
                            chart::Marker::diamond,
                            {frame_ms, frame_ms},
                            {lo, hi},
                            {}});
    panels.push_back(std::move(panel));
  }
  const chart::Canvas canvas = chart::plot_log_log(
      "pull frames on the " + args.executor + ": error against frame time", panels, 520, 420);
  write_canvas(args.out_dir / "live_speed.png", canvas);
}

// DIR/live_pull.png: the pull frames side by side, cropped around the first
// virtual object: what a viewer sees of the grain.
void write_pull_pictures(const LiveArgs &args, const Scene &scene,
                         const std::vector<RestCurve> &pull) {
  const auto first_virtual = std::find_if(scene.objects.begin(), scene.objects.end(),
                                          [](const Object &o) { return !o.real; });
  if (pull.empty() || first_virtual == scene.objects.end())
    return;
  // Where the object's centre lands: the pinhole projection.
  const gpu::FrameParams frame = make_frame_params(scene, scene_camera(scene));
  const glm::vec2 centre =
      project_to_pixel(frame, first_virtual->center).value_or(0.5f * glm::vec2(image_size(frame)));
  const int w = scene.render.width, h = scene.render.height;
  const int crop_w = std::min(w, 200), crop_h = std::min(h, 150);
  const int cx = int(centre.x);
  const int cy = int(centre.y);
  const int x0 = std::clamp(cx - crop_w / 2, 0, w - crop_w);
  const int y0 = std::clamp(cy - crop_h / 2, 0, h - crop_h);

  // Two lines a column: one line of the live frame's title is wider than
  // its picture.
  const std::array<std::array<std::string, 2>, 4> titles = {
      {{"1 RPP, FRESH", "(BEFORE)"},
       {"LIVE IN A PULL",
        rays_text(args.rpp) + " RPP" + (args.reconstruct > 0.0 ? ", RECONSTRUCTED" : "")},
       {"9 RPP", ""},
       {std::to_string(args.ref_rpp) + " RPP", "(REFERENCE)"}}};
  const int gap = 6, left = 120, top = 28;
  chart::Canvas canvas(left + 4 * (crop_w + gap), top + int(pull.size()) * (crop_h + gap),
                       {255, 255, 255});
  for (int col = 0; col < 4; ++col)
    for (int line = 0; line < 2; ++line)
      canvas.text(left + col * (crop_w + gap), 4 + 10 * line,
                  titles[std::size_t(col)][std::size_t(line)], {0, 0, 0});
  for (std::size_t row = 0; row < pull.size(); ++row) {
    const int oy = top + int(row) * (crop_h + gap);
    canvas.text(4, oy + crop_h / 2, fmt(pull[row].lens.focus_m, "%.2f M"), {0, 0, 0});
    for (std::size_t col = 0; col < pull[row].pictures.size() && col < 4; ++col) {
      const std::vector<std::uint8_t> &rgb = pull[row].pictures[col];
      const int ox = left + int(col) * (crop_w + gap);
      for (int y = 0; y < crop_h; ++y)
        for (int x = 0; x < crop_w; ++x) {
          const std::size_t i = (std::size_t(y0 + y) * std::size_t(w) + std::size_t(x0 + x)) * 3;
          canvas.set(ox + x, oy + y, {rgb[i], rgb[i + 1], rgb[i + 2]});
        }
    }
  }
  write_canvas(args.out_dir / "live_pull.png", canvas);
}

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

    std::printf("\n%s, %dx%d, reference %d rpp; live on the %s executor: %s rpp a frame at %.0f "
                "fps\n\n",
                scene_file.string().c_str(), scene.render.width, scene.render.height, args.ref_rpp,
                args.executor.c_str(), rays_text(args.rpp).c_str(), args.fps);
    std::printf("| still shot | region | uniform 1 / 9 / 49 rpp | live after 1 / 5 / 12 / 25 / "
                "%d frames | frames to 9 rpp's error | frames to 49 rpp's |\n|---|---|---|---|---|"
                "---|\n",
                args.frames);
    for (const RestCurve &c : rest) {
      const auto at = [&](int k) {
        return k <= int(c.error.size()) ? fmt(c.error[std::size_t(k - 1)]) : std::string("-");
      };
      const auto when = [&](double target) {
        const std::size_t k = frames_to(c, target);
        return k == 0 ? std::string("not in ") + std::to_string(c.error.size())
                      : std::to_string(k) + " (" + fmt(double(k) * frame_s, "%.2f") + " s)";
      };
      std::printf("| %s | %.1f %% | %s / %s / %s | %s / %s / %s / %s / %s | %s | %s |\n",
                  c.lens.name.c_str(), 100.0 * c.region, fmt(c.uniform1).c_str(),
                  fmt(c.uniform9).c_str(), fmt(c.uniform49).c_str(), at(1).c_str(), at(5).c_str(),
                  at(12).c_str(), at(25).c_str(), at(args.frames).c_str(), when(c.uniform9).c_str(),
                  when(c.uniform49).c_str());
    }
    std::printf("\n| pull frame | region | uniform 1 / 9 / 49 rpp | live, afresh | live, frames "
                "before moved (samples held) | against 9 rpp |\n|---|---|---|---|---|---|\n");
    for (const RestCurve &c : pull)
      std::printf("| %s | %.1f %% | %s / %s / %s | %s | %s (%u) | %.2fx |\n", c.lens.name.c_str(),
                  100.0 * c.region, fmt(c.uniform1).c_str(), fmt(c.uniform9).c_str(),
                  fmt(c.uniform49).c_str(), fmt(c.afresh).c_str(), fmt(c.error.front()).c_str(),
                  c.samples.front(), c.error.front() / c.uniform9);
    if (args.executor == "gpu")
      std::printf("\n(The GPU executor moves no samples through a new focus: its pull frames "
                  "start afresh either way.)\n");
    print_speed(args, pull);
    std::printf("\n");
    write_outputs(args, rest, pull);
    write_speed(args, pull);
    write_pull_pictures(args, scene, pull);
    return 0;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "bench live: %s\n", e.what());
    return 1;
  }
}

} // namespace

void add_bench_live_command(CLI::App &bench) {
  auto args = std::make_shared<LiveArgs>();
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
