// camhead bench live's reports (live_bench.h): the tables, the CSV files
// and the charts from the measurements that live_bench_command.cpp makes.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "camhead/renderer/frame_settings.h"
#include "chart/chart_plot.h"
#include "chart/chart_png.h"
#include "cli/live_bench.h"

namespace camhead::cli::live {
namespace {

namespace fs = std::filesystem;
using namespace renderer;

constexpr const char *kErrorLabel = "rel. RMSE over the region";

// The frame time of a fresh frame as accurate as `error`, in ms: log-log
// between the two fresh frames about it (their error falls as a power of
// their time); beyond those measured, "< " the quickest's or "> " the
// slowest's.
std::string fresh_ms_for(std::span<const TimedFrame> fresh, double error) {
  if (error >= fresh.front().error)
    return "< " + fmt(1e3 * fresh.front().seconds, "%.0f");
  for (std::size_t k = 0; k + 1 < fresh.size(); ++k) {
    const TimedFrame &a = fresh[k], &b = fresh[k + 1];
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
    chart::Panel panel{c.lens.name, "seconds since the lens came to rest", kErrorLabel, {}};
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
              kTimings, args.executor.c_str());
  for (const RestCurve &c : pull) {
    std::string fresh, live;
    for (const TimedFrame &t : c.uniform)
      fresh += (fresh.empty() ? "" : " / ") + fmt(1e3 * t.seconds, "%.1f");
    for (const TimedFrame &t : c.moved) {
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
    const auto rows = [&](const char *method, std::span<const TimedFrame> points,
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
    chart::Panel panel{c.lens.name, "ms a frame", kErrorLabel, {}};
    // Each point labelled with the rays a pixel it traced.
    const auto series = [](std::string name, chart::Rgb color, chart::Marker marker,
                           std::span<const TimedFrame> points) {
      chart::Series s{std::move(name), color, marker, {}, {}, {}};
      for (const TimedFrame &p : points) {
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

} // namespace

std::string fmt(double v, const char *format) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string rays_text(double rpp) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", rpp);
  return text;
}

void print_tables(const LiveArgs &args, const fs::path &scene_file, const Scene &scene,
                  const std::vector<RestCurve> &rest, const std::vector<RestCurve> &pull) {
  const double frame_s = 1.0 / args.fps;
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
}

void write_reports(const LiveArgs &args, const Scene &scene, const std::vector<RestCurve> &rest,
                   const std::vector<RestCurve> &pull) {
  write_outputs(args, rest, pull);
  write_speed(args, pull);
  write_pull_pictures(args, scene, pull);
}

} // namespace camhead::cli::live
