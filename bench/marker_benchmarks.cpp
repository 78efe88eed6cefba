// The marker pose source's time per frame (issue 25's benchmark: targets
// 5 ms at 720x576 and 12 ms at 1920x1080 on one core): the 9x6 ChArUco board
// of tests/markers at 2 m, seen from its side, through the module camhead
// opens at run time; and the same board too blurred to read, aligned whole. The module runs OpenCV
// on one thread (it tracks while the renderer has the other cores).
//
//   build/bench/marker_benchmarks --benchmark_repetitions=9
#include <cmath>
#include <cstdlib>
#include <memory>
#include <random>

#include <glm/geometric.hpp>
#include <opencv2/imgproc.hpp>

#include "synthetic_view.h"
#include "tracking/marker_board.h"
#include "tracking/marker_tracker.h"

#include <benchmark/benchmark.h>

namespace {

using namespace camhead::pipeline;

const bool kModuleFound = setenv("CAMHEAD_MARKERS_MODULE", CAMHEAD_BENCH_MARKERS_MODULE, 0) == 0;

void Track(benchmark::State &state) {
  const int width = int(state.range(0)), height = int(state.range(1));
  const MarkerBoard board = test::floor_board();
  const CameraModel camera = test::pinhole(width, height);
  const glm::dvec3 centre = test::kFloorBoardCentre;
  camhead::renderer::FrameCamera c;
  c.position = glm::vec3(centre + 2.0 * glm::normalize(glm::dvec3(0.6, 1.3, 1.4)));
  c.look_at = glm::vec3(centre);
  std::mt19937 random(1);
  const cv::Mat picture =
      test::frame(test::charuco_view(board, camera, pose_of(c), {width, height}), 1.0, random);
  const auto tracker = open_marker_tracker(board);
  const LumaImage luma{picture.data, picture.cols, picture.rows, std::ptrdiff_t(picture.step)};
  MarkerPose pose;
  for (auto _ : state) {
    pose = tracker->track(luma, camera, nullptr);
    benchmark::DoNotOptimize(pose);
  }
  if (!pose.found)
    state.SkipWithError("the board was not found");
  state.counters["corners"] = pose.points_used;
}
BENCHMARK(Track)->Args({720, 576})->Args({1920, 1080})->Unit(benchmark::kMillisecond);

// A board too blurred to read, aligned whole (the marker module's
// BoardAligner): 11 px of defocus at 720x576 (the same lens at 1920x1080:
// 29 px), guided by the sharp frame's pose, from the side (range 0 = 0) or
// from its bottom edge, a 37-degree view whose squares are foreshortened
// 1.7 times (1); ranges 1 and 2: the picture's size.
void TrackBlurred(benchmark::State &state) {
  const int width = int(state.range(1)), height = int(state.range(2)),
            blur = int(std::lround(11.0 * width / 720.0));
  const MarkerBoard board = test::floor_board();
  const CameraModel camera = test::pinhole(width, height);
  const glm::dvec3 centre = test::kFloorBoardCentre;
  camhead::renderer::FrameCamera c;
  c.position =
      glm::vec3(centre + 2.0 * glm::normalize(state.range(0) == 0 ? glm::dvec3(0.6, 1.3, 1.4)
                                                                  : glm::dvec3(0.0, 1.2, 1.6)));
  c.look_at = glm::vec3(centre);
  std::mt19937 random(1);
  const cv::Mat sharp = test::charuco_view(board, camera, pose_of(c), {width, height});
  cv::Mat disc(2 * blur + 1, 2 * blur + 1, CV_32F, cv::Scalar(0));
  cv::circle(disc, {blur, blur}, blur / 2, cv::Scalar(1), cv::FILLED);
  cv::Mat blurred;
  cv::filter2D(sharp, blurred, -1, disc / cv::sum(disc)[0], cv::Point(-1, -1), 0.0,
               cv::BORDER_REPLICATE);
  const cv::Mat first = test::frame(sharp, 1.0, random),
                picture = test::frame(blurred, 1.0, random);
  const auto tracker = open_marker_tracker(board);
  const MarkerPose guide = tracker->track(
      {first.data, first.cols, first.rows, std::ptrdiff_t(first.step)}, camera, nullptr);
  CameraModel lens = camera;
  lens.defocus_px = 2.0 * blur; // focused at infinity: blur px at the board's 2 m
  const LumaImage luma{picture.data, picture.cols, picture.rows, std::ptrdiff_t(picture.step)};
  MarkerPose pose;
  for (auto _ : state) {
    pose = tracker->track(luma, lens, &guide.pose);
    benchmark::DoNotOptimize(pose);
  }
  if (!pose.found || !pose.aligned)
    state.SkipWithError("the board was not aligned");
  // How far the aligned camera is from the one that drew the view.
  state.counters["off_mm"] = 1e3 * glm::length(pose.pose.position - pose_of(c).position);
}
BENCHMARK(TrackBlurred)
    ->Args({0, 720, 576})
    ->Args({1, 720, 576})
    ->Args({0, 1920, 1080})
    ->Args({1, 1920, 1080})
    ->Unit(benchmark::kMillisecond);

} // namespace

BENCHMARK_MAIN();
