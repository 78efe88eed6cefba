// The marker pose source's time per frame (issue 25's benchmark: targets
// 5 ms at 720x576 and 12 ms at 1920x1080 on one core): the 9x6 ChArUco board
// of tests/markers at 2 m, seen from its side, through the module camhead
// opens at run time. The module runs OpenCV on one thread (it tracks while
// the renderer has the other cores).
//
//   build/bench/marker_benchmarks --benchmark_repetitions=9
#include <cstdlib>
#include <memory>
#include <random>

#include <glm/geometric.hpp>

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

} // namespace

BENCHMARK_MAIN();
