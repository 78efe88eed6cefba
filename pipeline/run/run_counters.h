// What the live pipeline's threads count as they go (run_loop.cpp): the
// status line (run_status.h) and the run's summary read them.
#pragma once

#include <atomic>
#include <cstdint>

namespace camhead::pipeline {

struct RunCounters {
  std::atomic<std::uint64_t> frames_in{0}, frames_out{0}, render_busy{0}, output_busy{0},
      render_failed{0}, placeholders{0}, repeats{0}, sink_errors{0}, lens_late{0};
  std::atomic<double> rpp{0.0}; // rays per pixel asked of the last frame, a mean
  std::atomic<std::uint32_t> traced_permille{1000}; // of the last frame's pixels
  std::atomic<std::int64_t> latency_ns{0};          // capture to output, last frame
  std::atomic<bool> camera_lost{false};
  std::atomic<bool> pose_stale{false};    // the last frame's pose was held or predicted
  std::atomic<bool> pose_unknown{false};  // no pose yet: the last frame was the camera image alone
  std::atomic<bool> renderer_lost{false}; // the GPU is gone: placeholders from now on
};

} // namespace camhead::pipeline
