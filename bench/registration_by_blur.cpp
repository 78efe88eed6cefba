// Registration of a moving simulated rig against the truth, by the blur of
// its marker board (issue 25, "What must be shown" 2 and 3, on the rig that
// README's moving example runs): reads the record of a `camhead run` of a
// board whose simulated camera follows a camera path and whose pose comes
// from a marker board, and for each composite whose pose was found in its
// own frame, how far the recorded pose puts the points that register the
// virtual world to the real one (the board's outer corners, the scene's
// virtual objects' centres) from where the path's true pose at that frame's
// mid-exposure puts them, in pixels, against the blur circle of the board's
// centre in that frame. Both poses are seen through the lens the simulated
// camera filmed with at that instant (the board's trace as the glass moved,
// run/trace_lens.h): from its entrance pupil, at its projection focal
// length, and its thin-lens blur. The composites before the board was first
// found (the camera image alone: `pose_known` false) are left out.
//
//   build/camhead run --board sim-moving --duration 60 --output null --record-stats m.jsonl
//   build/bench/registration_by_blur board/sim-moving.json m.jsonl [OUT]
//
// Prints a table by blur (frames, median and worst registration, median
// reprojection error), then one by how each pose was found (on the board
// and at the virtual objects, how far the registration jumps from one
// composite to the next, how far out it puts the board's corners: a scale
// error, and the frames' tracking time where the record has it), then one
// of every found frame predicted as if its tracking had come late (the
// marker source's rule, marker_source.h, against the 20 ms it had before);
// OUT.csv gets a row per frame and OUT.png the chart.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <limits>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "camhead/renderer/scene_loader.h"
#include "chart/chart_plot.h"
#include "chart/chart_png.h"
#include "config/board.h"
#include "run/trace_lens.h"
#include "tracking/marker_board.h"
#include "tracking/marker_source.h"
#include "tracking/pose_timeline.h"
#include "tracking/pose_trace.h"

namespace {

using namespace camhead::pipeline;
namespace chart = camhead::cli::chart;

struct Frame {
  bool found = false;      // the pose was found in this frame (else held or predicted)
  std::int64_t mid_ns = 0; // mid-exposure, CLOCK_MONOTONIC: the path's clock
  CameraPose seen;         // the recorded pose
  double t_s = 0;          // mid-exposure, on the path's clock
  double blur_px = 0;      // the board's centre
  double registration = 0; // px, the largest over the points
  double reprojection = 0; // px, the tracker's own residual
  int markers = 0;
  // The largest registration on the board's own outer corners and at the
  // virtual objects' centres (farther from the board, where an error of
  // the board's tilt grows).
  double on_board = 0, at_virtual = 0;
  // The mean of the board's outer corners' errors along the way out from
  // the board's centre in the picture: positive, the board registered too
  // large (a scale error that a median of distances hides).
  double outward = 0;
  // The largest change of a point's registration since the composite
  // before, px: how far the virtual world jumps against the real one (the
  // camera's own motion taken out).
  double jump = 0;
  std::string found_by; // the record's pose_found_by; empty: null
  // The frame's tracking time (the record's track_ms), NaN where the
  // record has none.
  double track_ms = std::numeric_limits<double>::quiet_NaN();
};

CameraPose recorded_pose(const nlohmann::json &pose) {
  const auto vec = [&](const char *key) {
    const auto &a = pose.at(key);
    return glm::dvec3(a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>());
  };
  const glm::dvec3 forward = glm::normalize(vec("forward"));
  const glm::dvec3 right = glm::normalize(glm::cross(forward, vec("up")));
  const glm::dmat3 axes(right, glm::cross(right, forward), -forward); // right, up, back
  return {vec("position"), glm::normalize(glm::quat_cast(axes))};
}

// A centred pinhole at the entrance pupil, `pupil_m` ahead of the pose's
// reference plane: the recorded and the true pose are compared through the
// same camera, so the lens's distortion cancels to first order.
glm::dvec2 pixel(const CameraPose &pose, const glm::dvec3 &point, int width, int height,
                 double focal_px, double pupil_m) {
  const glm::dvec3 p =
      glm::inverse(pose.orientation) * (point - pose.position - pose.forward() * pupil_m);
  return {width / 2.0 + focal_px * p.x / -p.z, height / 2.0 - focal_px * p.y / -p.z};
}

// The thin lens's blur circle of a point `depth_m` in front of the entrance
// pupil, in pixels of a projection focal length of `focal_px`:
// f_px (f / N) |1/s - 1/d|, focus s from the pupil too (infinity allowed).
double blur_px(double depth_m, const camhead::lens_control::LensState &lens, double focal_px) {
  const double aperture_m = lens.focal_length_mm.value * 1e-3 / lens.f_number.value;
  return focal_px * aperture_m * std::abs(1.0 / lens.focus_distance_m.value - 1.0 / depth_m);
}

double quantile(std::vector<double> v, double q) {
  if (v.empty())
    return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  return v[std::size_t(std::lround(q * double(v.size() - 1)))];
}

int run(int argc, char **argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: registration_by_blur BOARD.json RECORD.jsonl [OUT]\n");
    return 2;
  }
  const Board board = load_board(argv[1]);
  const auto *sim = board.camera ? std::get_if<SimCameraConfig>(&board.camera->kind) : nullptr;
  if (sim == nullptr || !sim->path || !board.pose || board.pose->type != PoseType::marker ||
      !board.scene)
    throw std::runtime_error(std::string(argv[1]) +
                             ": wants a simulated camera with a path, a scene and a marker pose");
  const PoseTrace truth = load_pose_trace(*sim->path);
  const std::optional<TraceLens> lens = TraceLens::of_board(board);
  if (!lens)
    throw std::runtime_error(std::string(argv[1]) +
                             ": wants a lens trace replayed on the monotonic clock (the truth)");
  const MarkerBoard markers = load_marker_board(board.pose->file);
  const camhead::renderer::Scene scene = camhead::renderer::load_scene(*board.scene);
  const int width = board.camera->width, height = board.camera->height;
  const double sx = markers.squares_x * markers.square_m, sz = markers.squares_y * markers.square_m;
  const glm::dvec3 centre(sx / 2, 0, sz / 2);
  std::vector<glm::dvec3> points = {{0, 0, 0}, {sx, 0, 0}, {0, 0, sz}, {sx, 0, sz}};
  const std::size_t board_points = points.size();
  for (const auto &object : scene.objects)
    if (!object.real)
      points.emplace_back(object.center);
  std::vector<glm::dvec2> error_before(points.size());
  // Where `seen` puts each point at mid-exposure `mid`, less where the
  // path's true pose puts it, through the lens filmed with then.
  std::vector<glm::dvec2> errors(points.size());
  const auto errors_at = [&](const CameraPose &seen, std::int64_t mid) {
    const CameraPose real = truth.at(mid);
    const camhead::lens_control::LensState filmed = lens->state_at(mid);
    const double focal_px =
        filmed.projection_focal_length_mm.value / board.camera->sensor_width_mm * width;
    const double pupil_m = filmed.entrance_pupil_offset_mm.value * 1e-3;
    for (std::size_t i = 0; i < points.size(); ++i)
      errors[i] = pixel(seen, points[i], width, height, focal_px, pupil_m) -
                  pixel(real, points[i], width, height, focal_px, pupil_m);
  };

  std::ifstream in(argv[2]);
  if (!in)
    throw std::runtime_error(std::string("cannot read ") + argv[2]);
  // The composites before the pose source's first pose have no virtual
  // objects (`pose_known` false; in records without it, as `rig_tracking`
  // writes them, those before the first pose found in its frame): counted,
  // left out.
  std::vector<Frame> frames;
  int composites = 0, before_first = 0;
  for (std::string line; std::getline(in, line);) {
    const nlohmann::json r = nlohmann::json::parse(line);
    if (r.value("kind", "") != "composite")
      continue;
    ++composites;
    const bool before_first_pose = r.contains("pose_known")
                                       ? !r.at("pose_known").get<bool>()
                                       : frames.empty() && !r.value("pose_fresh", false);
    if (before_first_pose) {
      ++before_first;
      continue;
    }
    const std::int64_t mid = r.at("exposure_mid_ns").get<std::int64_t>();
    const CameraPose real = truth.at(mid), seen = recorded_pose(r.at("pose"));
    const camhead::lens_control::LensState filmed = lens->state_at(mid);
    const double focal_px =
        filmed.projection_focal_length_mm.value / board.camera->sensor_width_mm * width;
    const double pupil_m = filmed.entrance_pupil_offset_mm.value * 1e-3;
    Frame f;
    f.found = r.value("pose_fresh", false);
    f.mid_ns = mid;
    f.seen = seen;
    f.t_s = double(mid) * 1e-9;
    f.blur_px =
        blur_px(glm::dot(centre - real.position, real.forward()) - pupil_m, filmed, focal_px);
    glm::dvec2 board_centre(0.0);
    for (std::size_t i = 0; i < board_points; ++i)
      board_centre += pixel(real, points[i], width, height, focal_px, pupil_m);
    board_centre /= double(board_points);
    errors_at(seen, mid);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const glm::dvec2 error = errors[i];
      double &part = i < board_points ? f.on_board : f.at_virtual;
      part = std::max(part, glm::length(error));
      if (i < board_points) {
        const glm::dvec2 out =
            glm::normalize(pixel(real, points[i], width, height, focal_px, pupil_m) - board_centre);
        f.outward += glm::dot(error, out) / double(board_points);
      }
      if (!frames.empty())
        f.jump = std::max(f.jump, glm::length(error - error_before[i]));
      error_before[i] = error;
    }
    f.registration = std::max(f.on_board, f.at_virtual);
    if (const auto &by = r.at("pose_found_by"); by.is_string())
      f.found_by = by.get<std::string>();
    f.reprojection =
        r.at("reprojection_px").is_null() ? 0.0 : r.at("reprojection_px").get<double>();
    f.markers = r.value("markers_seen", 0);
    if (const auto t = r.find("track_ms"); t != r.end() && t->is_number())
      f.track_ms = t->get<double>();
    frames.push_back(f);
  }

  const auto found =
      std::count_if(frames.begin(), frames.end(), [](const Frame &f) { return f.found; });
  std::printf("%d composites; %d before the board was first found (left out); %td of the rest "
              "with the pose found in the frame\n\n",
              composites, before_first, found);
  std::printf("| board's blur circle | pose found in the frame: frames | registration median | "
              "p90 | worst | reprojection median | pose held or predicted: frames | "
              "registration median | worst |\n|---|---|---|---|---|---|---|---|---|\n");
  const double edges[] = {0, 1, 2, 3, 4, 6, 10, 1e9};
  // The chart: per bin of blur, at its middle (the last at 14 px).
  std::vector<chart::Series> series = {
      {"median", {31, 119, 180}, chart::Marker::circle, {}, {}, {}},
      {"worst", {214, 39, 40}, chart::Marker::triangle, {}, {}, {}},
      {"median", {31, 119, 180}, chart::Marker::circle, {}, {}, {}},
      {"worst", {214, 39, 40}, chart::Marker::triangle, {}, {}, {}}};
  const auto add = [&](std::size_t i, double x, double y) {
    if (std::isfinite(y)) {
      series[i].x.push_back(x);
      series[i].y.push_back(std::max(y, 0.01));
    }
  };
  for (std::size_t b = 0; b + 1 < std::size(edges); ++b) {
    std::vector<double> reg, rep, held;
    for (const Frame &f : frames)
      if (f.blur_px >= edges[b] && f.blur_px < edges[b + 1]) {
        (f.found ? reg : held).push_back(f.registration);
        if (f.found)
          rep.push_back(f.reprojection);
      }
    if (reg.empty() && held.empty())
      continue;
    const std::string bin = edges[b + 1] > 1e8 ? std::to_string(int(edges[b])) + " px and more"
                                               : std::to_string(int(edges[b])) + "-" +
                                                     std::to_string(int(edges[b + 1])) + " px";
    std::printf("| %s | %zu | %.3f px | %.3f px | %.3f px | %.3f px | %zu | %.3f px | %.3f px |\n",
                bin.c_str(), reg.size(), quantile(reg, 0.5), quantile(reg, 0.9), quantile(reg, 1.0),
                quantile(rep, 0.5), held.size(), quantile(held, 0.5), quantile(held, 1.0));
    const double x = edges[b + 1] > 1e8 ? 14.0 : std::max(0.5 * (edges[b] + edges[b + 1]), 0.5);
    add(0, x, quantile(reg, 0.5));
    add(1, x, quantile(reg, 1.0));
    add(2, x, quantile(held, 0.5));
    add(3, x, quantile(held, 1.0));
  }

  // Where the error is and how it moves, by how the pose was found: a
  // planar board pins its own corners better than points off it, and a
  // pose measured afresh each frame jitters (the jump).
  std::printf(
      "\n| found by | frames | on the board: median, p90, worst | at the virtual objects: "
      "median, p90, worst | within 1 px | jump since the composite before: median, p99, "
      "worst | outward: median | tracking: median, p90 |\n|---|---|---|---|---|---|---|---|\n");
  for (const char *by : {"markers", "corners", "alignment"}) {
    std::vector<double> board_px, virtual_px, jump_px, outward_px, track_ms;
    std::size_t within = 0;
    for (const Frame &f : frames)
      if (f.found && f.found_by == by) {
        board_px.push_back(f.on_board);
        virtual_px.push_back(f.at_virtual);
        jump_px.push_back(f.jump);
        outward_px.push_back(f.outward);
        if (std::isfinite(f.track_ms))
          track_ms.push_back(f.track_ms);
        within += f.registration <= 1.0 ? 1 : 0;
      }
    if (board_px.empty())
      continue;
    std::printf("| %s | %zu | %.2f, %.2f, %.2f px | %.2f, %.2f, %.2f px | %.1f %% | %.2f, %.2f, "
                "%.2f px | %+.2f px | %.2f, %.2f ms |\n",
                by, board_px.size(), quantile(board_px, 0.5), quantile(board_px, 0.9),
                quantile(board_px, 1.0), quantile(virtual_px, 0.5), quantile(virtual_px, 0.9),
                quantile(virtual_px, 1.0), 100.0 * double(within) / double(board_px.size()),
                quantile(jump_px, 0.5), quantile(jump_px, 0.99), quantile(jump_px, 1.0),
                quantile(outward_px, 0.5), quantile(track_ms, 0.5), quantile(track_ms, 0.9));
  }

  // Each frame found as if its tracking had come late: predicted from the
  // frames found before it, by the marker source's rule and by the one it
  // had before (20 ms of the last two poses' motion, then held). A frame
  // late in the run itself is rare (under load), this is every frame.
  const std::int64_t interval_ns = std::llround(1e9 / sim->fps);
  PoseTimelineParams before_params = predicted_pose_params(interval_ns);
  before_params.max_extrapolation_ns = 20'000'000;
  before_params.stale_after_ns = 50'000'000;
  std::printf("\n| each found frame predicted as if late, by | frames | registration: median, "
              "p90, p99, worst | within 1 px |\n|---|---|---|---|\n");
  for (const auto &[rule, params] : {std::pair{"the marker source (a frame interval on, up to two)",
                                               predicted_pose_params(interval_ns)},
                                     std::pair{"20 ms on, then held (before)", before_params}}) {
    PoseTimeline found_before(params);
    std::vector<double> predicted_px;
    for (const Frame &f : frames) {
      if (!f.found)
        continue;
      if (found_before.size() >= 2) {
        errors_at(found_before.at(f.mid_ns)->pose, f.mid_ns);
        double worst = 0.0;
        for (const glm::dvec2 &e : errors)
          worst = std::max(worst, glm::length(e));
        predicted_px.push_back(worst);
      }
      (void)found_before.push(f.mid_ns, f.seen);
    }
    const auto within = std::count_if(predicted_px.begin(), predicted_px.end(),
                                      [](double px) { return px <= 1.0; });
    std::printf("| %s | %zu | %.2f, %.2f, %.2f, %.2f px | %.1f %% |\n", rule, predicted_px.size(),
                quantile(predicted_px, 0.5), quantile(predicted_px, 0.9),
                quantile(predicted_px, 0.99), quantile(predicted_px, 1.0),
                predicted_px.empty() ? 0.0 : 100.0 * double(within) / double(predicted_px.size()));
  }

  if (argc == 4) {
    const std::string out = argv[3];
    std::ofstream csv(out + ".csv");
    csv << "t_s,pose_found,found_by,blur_px,registration_px,on_board_px,at_virtual_px,jump_px,"
           "reprojection_px,markers_seen,outward_px,track_ms\n";
    for (const Frame &f : frames) {
      char row[220];
      std::snprintf(row, sizeof row, "%.4f,%d,%s,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%d,%.4f,%.3f\n",
                    f.t_s, int(f.found), f.found_by.c_str(), f.blur_px, f.registration, f.on_board,
                    f.at_virtual, f.jump, f.reprojection, f.markers, f.outward, f.track_ms);
      csv << row;
    }
    const chart::Panel panels[] = {{"pose found in the frame",
                                    "board's blur, px (0-1 at 0.5)",
                                    "registration, px",
                                    {series[0], series[1]}},
                                   {"pose held or predicted",
                                    "board's blur, px (0-1 at 0.5)",
                                    "registration, px",
                                    {series[2], series[3]}}};
    const chart::Canvas canvas =
        chart::plot_log_log("Moving rig: registration by the board's blur", panels, 480, 400);
    chart::write_png(out + ".png", canvas);
    std::printf("\nwrote %s.csv and %s.png\n", out.c_str(), out.c_str());
  }
  return 0;
}

} // namespace

int main(int argc, char **argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "registration_by_blur: %s\n", e.what());
    return 1;
  }
}
