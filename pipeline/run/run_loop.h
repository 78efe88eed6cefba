// The live pipeline (`camhead run`): camera frames and the lens in,
// composited video out.
//
//   capture thread   camera.wait_frame() -> [queue of 1, newest wins] ->
//   render thread    lens state at mid-exposure, FrameBudget's rays per
//                    pixel, FrameRenderer into a free output slot ->
//                    [queue of slots] ->
//   output thread    each sink: acquire, copy, submit; the per-frame record;
//                    after half a second without a composite, the last one
//                    again, or a placeholder while there is no camera
//   lens thread      (LensHub) every lens source into its tracker
//
// A slower stage never makes a faster one wait: the render thread always
// takes the newest camera frame (the one it replaces is dropped and
// counted, "render busy"), and a frame with no free output slot is dropped
// ("output busy"). Nothing in the loop throws; a camera that goes away is
// waited for while the outputs show the placeholder.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "board.h"

namespace camhead::pipeline {

struct RunOptions {
  Board board;
  std::vector<std::string> outputs; // URIs; empty: the board's
  double duration_s = 0.0;          // 0: until stopped
  std::uint64_t frames = 0;         // output frames; 0: until stopped
  std::optional<std::filesystem::path> stats_file;
  std::optional<Executor> executor; // overrides the board's
  int threads = 0;                  // CPU executor; <= 0: one per hardware thread
  // Trace only where the virtual objects can change the composite
  // (renderer influence_region.h); false traces every pixel, for comparison.
  bool influence_region = true;
  // A consumer (a browser on the loopback webcam) must never go a second
  // without a frame: after this long without a composite, the last one
  // again, or the placeholder while there is no camera (or none yet).
  double repeat_after_s = 0.5;
  std::FILE *status = stderr; // the status line; null: none
  const std::atomic<bool> *stop = nullptr;
};

struct RunSummary {
  std::uint64_t frames_in = 0;  // camera frames captured
  std::uint64_t frames_out = 0; // composites sent to the outputs
  std::uint64_t camera_dropped = 0;
  std::uint64_t camera_errors = 0;
  std::uint64_t camera_reconnects = 0;
  std::uint64_t render_busy = 0; // camera frames replaced by a newer one before rendering
  std::uint64_t output_busy = 0; // composites without a free output slot
  std::uint64_t render_failed = 0;
  std::uint64_t placeholders = 0; // placeholder frames sent (no camera, or none yet)
  std::uint64_t repeats = 0;      // the last composite sent again (the camera was slow)
  std::uint64_t sink_errors = 0;
  double seconds = 0.0;
  std::string executor;
};

// The statistics file (--record-stats) cannot be opened or written.
class StatsFileError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// Sets everything up (throws std::runtime_error naming the board field,
// file or device at fault before any output is written), runs until
// `frames`, `duration_s` or `*stop`, and closes the outputs. Throws
// StatsFileError when the statistics could not all be written.
RunSummary run_pipeline(const RunOptions &options);

} // namespace camhead::pipeline
