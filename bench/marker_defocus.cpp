// The marker pose against the blur of the board (issue 25, "What must be
// shown" 3): the 9x6 ChArUco board of tests/markers at 2 m, seen from three
// directions, blurred by a defocused lens's disc of D pixels (the same over
// the whole board: a flat board at one depth), 20 frames of 1 DN sensor
// noise each, the tracker guided by the pose found in a sharp frame first
// (a focus pull starts sharp), and told the lens's defocus (D at the
// board's 2 m). For each D: how often a pose is found (and how often by
// following the board's corners from the pose before, or by aligning the
// whole board drawn blurred, its markers unreadable), its median and worst
// position and orientation error, how far it puts the board's outer corners
// in the picture (median and worst), and the largest step between the poses of
// consecutive frames of the still camera (what a viewer sees as a jump).
//
//   build/bench/marker_defocus bench/marker_defocus   (writes .csv and .png)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "chart/chart_plot.h"
#include "chart/chart_png.h"
#include "synthetic_view.h"
#include "tracking/marker_board.h"
#include "tracking/marker_tracker.h"

namespace {

using namespace camhead::pipeline;
namespace chart = camhead::cli::chart;

const bool kModuleFound = setenv("CAMHEAD_MARKERS_MODULE", CAMHEAD_BENCH_MARKERS_MODULE, 0) == 0;

constexpr int kWidth = 720, kHeight = 576, kFrames = 20;

// A defocused lens's blur: a uniform disc of `diameter` pixels, its edge
// antialiased.
cv::Mat disc(double diameter) {
  const int r = int(std::ceil(diameter / 2.0));
  cv::Mat k(2 * r + 1, 2 * r + 1, CV_32F);
  for (int y = -r; y <= r; ++y)
    for (int x = -r; x <= r; ++x) {
      double inside = 0.0; // 4x4 samples of the pixel
      for (int sy = 0; sy < 4; ++sy)
        for (int sx = 0; sx < 4; ++sx) {
          const double px = x + (sx + 0.5) / 4.0 - 0.5, py = y + (sy + 0.5) / 4.0 - 0.5;
          inside += px * px + py * py <= diameter * diameter / 4.0 ? 1.0 / 16.0 : 0.0;
        }
      k.at<float>(y + r, x + r) = float(inside);
    }
  return k / cv::sum(k)[0];
}

double degrees_between(const glm::dquat &a, const glm::dquat &b) {
  return 2.0 * std::acos(std::min(1.0, std::abs(glm::dot(a, b)))) * 180.0 / std::numbers::pi;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty())
    return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, std::size_t(p * double(v.size() - 1) + 0.5))];
}

} // namespace

int main(int argc, char **argv) {
  const std::string out = argc > 1 ? argv[1] : "marker_defocus";
  const MarkerBoard board = test::floor_board();
  const CameraModel camera = test::pinhole(kWidth, kHeight);
  const glm::dvec3 centre = test::kFloorBoardCentre;
  const glm::dvec3 directions[] = {{0.0, 1.2, 1.6}, {0.6, 1.3, 1.4}, {0.1, 0.75, 1.8}};
  const double diameters[] = {0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 11.0, 16.0};
  const auto tracker = open_marker_tracker(board);
  // How far a pose puts the board's outer corners from where the truth
  // does, pixels, the worst of them: what a viewer sees (a camera position
  // off along a planar board's weak direction moves them little).
  const auto corners_px = [&](const CameraPose &pose, const CameraPose &truth) {
    const double w = board.squares_x * board.square_m, h = board.squares_y * board.square_m;
    const auto pixel = [&](const CameraPose &at, const glm::dvec3 &p) {
      const glm::dvec3 v = glm::inverse(at.orientation) * (p - at.position);
      return glm::dvec2(camera.cx + camera.fx * v.x / -v.z, camera.cy - camera.fy * v.y / -v.z);
    };
    double worst = 0.0;
    for (const glm::dvec3 &corner :
         {glm::dvec3(0.0), glm::dvec3(w, 0.0, 0.0), glm::dvec3(0.0, 0.0, h), glm::dvec3(w, 0.0, h)})
      worst = std::max(worst, glm::length(pixel(pose, corner) - pixel(truth, corner)));
    return worst;
  };
  std::mt19937 random(7);

  std::ofstream csv(out + ".csv");
  csv << "blur_px,view,found,followed,aligned,frames,median_mm,worst_mm,median_deg,worst_deg,"
         "largest_step_mm,markers_median,median_px,worst_px\n";
  std::vector<chart::Series> position(3), steps(3);
  const chart::Rgb colors[] = {{31, 119, 180}, {214, 39, 40}, {44, 160, 44}};
  const char *names[] = {"from the bottom edge", "from the right", "shallow"};
  for (int v = 0; v < 3; ++v) {
    position[std::size_t(v)] = {names[v], colors[v], chart::Marker(v), {}, {}, {}};
    steps[std::size_t(v)] = {names[v], colors[v], chart::Marker(v), {}, {}, {}};
  }
  for (int v = 0; v < 3; ++v) {
    camhead::renderer::FrameCamera c;
    c.position = glm::vec3(centre + 2.0 * glm::normalize(directions[v]));
    c.look_at = glm::vec3(centre);
    CameraPose truth = pose_of(c);
    truth.position = centre + 2.0 * glm::normalize(directions[v]);
    const cv::Mat sharp = test::charuco_view(board, camera, truth, {kWidth, kHeight});
    // A focus pull starts sharp: the pose found there is the tracker's
    // guide into the blur, as the frames before are in `camhead run`.
    const cv::Mat first = test::frame(sharp, 1.0, random);
    const MarkerPose start = tracker->track(
        {first.data, first.cols, first.rows, std::ptrdiff_t(first.step)}, camera, nullptr);
    for (const double d : diameters) {
      cv::Mat light = sharp;
      if (d > 0.0)
        cv::filter2D(sharp, light, -1, disc(d), cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
      // The lens that blurs the board by d at its 2 m (focused at infinity),
      // which the tracker draws the board with where it cannot read it.
      CameraModel lens = camera;
      lens.defocus_px = 2.0 * d;
      std::vector<double> mm, deg, px, step, markers;
      std::optional<CameraPose> previous;
      if (start.found)
        previous = start.pose;
      int found = 0, followed = 0, aligned = 0;
      bool first_step = true;
      for (int f = 0; f < kFrames; ++f) {
        const cv::Mat picture = test::frame(light, 1.0, random);
        const MarkerPose got =
            tracker->track({picture.data, picture.cols, picture.rows, std::ptrdiff_t(picture.step)},
                           lens, previous ? &*previous : nullptr);
        markers.push_back(got.markers_seen);
        if (!got.found)
          continue;
        ++found;
        followed += got.followed ? 1 : 0;
        aligned += got.aligned ? 1 : 0;
        mm.push_back(1000.0 * glm::length(got.pose.position - truth.position));
        deg.push_back(degrees_between(got.pose.orientation, truth.orientation));
        px.push_back(corners_px(got.pose, truth));
        if (!first_step) // the first step is from the sharp frame's pose
          step.push_back(1000.0 * glm::length(got.pose.position - previous->position));
        first_step = false;
        previous = got.pose;
      }
      const double worst_step = step.empty() ? 0.0 : *std::max_element(step.begin(), step.end());
      csv << d << "," << v << "," << found << "," << followed << "," << aligned << "," << kFrames
          << "," << percentile(mm, 0.5) << "," << percentile(mm, 1.0) << "," << percentile(deg, 0.5)
          << "," << percentile(deg, 1.0) << "," << worst_step << "," << percentile(markers, 0.5)
          << "," << percentile(px, 0.5) << "," << percentile(px, 1.0) << "\n";
      std::printf("blur %4.1f px, %-20s found %2d/%d (followed %2d, aligned %2d)  median %.3f mm  "
                  "worst %.3f mm  %.4f deg  corners %.2f / %.2f px  largest step %.3f mm  "
                  "markers %.0f\n",
                  d, names[v], found, kFrames, followed, aligned, percentile(mm, 0.5),
                  percentile(mm, 1.0), percentile(deg, 1.0), percentile(px, 0.5),
                  percentile(px, 1.0), worst_step, percentile(markers, 0.5));
      // Log axes: a sharp board at a quarter of a pixel.
      const double x = d > 0.0 ? d : 0.25;
      if (found > 0) {
        position[std::size_t(v)].x.push_back(x);
        position[std::size_t(v)].y.push_back(percentile(mm, 1.0));
        position[std::size_t(v)].labels.push_back(std::to_string(found));
        steps[std::size_t(v)].x.push_back(x);
        steps[std::size_t(v)].y.push_back(std::max(worst_step, 1e-3));
      }
    }
  }
  const chart::Panel panels[] = {{"worst position error, 20 frames (labels: with a pose)",
                                  "blur diameter px (sharp at 0.25)", "mm", position},
                                 {"largest step frame to frame, still camera",
                                  "blur diameter px (sharp at 0.25)", "mm", steps}};
  const chart::Canvas canvas = chart::plot_log_log(
      "ChArUco 9x6 of 10 cm at 2 m, 720x576, 35 mm, 1 DN noise: pose against defocus", panels);
  chart::write_png(out + ".png", canvas);
  std::printf("wrote %s.csv and %s.png\n", out.c_str(), out.c_str());
  return 0;
}
