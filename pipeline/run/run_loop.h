// The live pipeline (`camhead run`): camera frames and the lens in,
// composited video out.
//
//   capture thread   camera.wait_frame() -> [queue of 1, newest wins] ->
//   render thread    lens state at mid-exposure (waiting for it, bounded,
//                    while its readings are still coming), FrameBudget's
//                    rays per pixel, FrameRenderer into a free output slot ->
//                    [queue of slots] ->
//   output thread    each sink: submit from the slot; the per-frame record;
//                    after half a second without a composite, the last one
//                    again, or a placeholder while there is no camera
//   lens thread      (LensHub) every lens source into its tracker
//
// A slower stage never makes a faster one wait: the render thread always
// takes the newest camera frame (the one it replaces is dropped and
// counted, "render busy"), and a frame with no free output slot is dropped
// ("output busy"). Nothing in the loop throws; a camera that goes away is
// waited for while the outputs show the placeholder. A take played once
// that breaks off ends the run, and the summary says where
// (RunSummary::camera_failure).
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/board.h"
#include "web/web_access.h"

namespace camhead::pipeline {

class ServiceNotifier;

struct RunOptions {
  Board board;
  std::vector<std::string> outputs; // URIs; empty: the board's
  double duration_s = 0.0;          // 0: until stopped
  std::uint64_t frames = 0;         // composites output; 0: until stopped
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
  // systemd's notification socket (service/service_notifier.h): READY=1
  // once the first frame is out, the status line as STATUS=, WATCHDOG=1
  // while the output advances (service/output_watchdog.h), STOPPING=1 at
  // the end. Null or inactive: none.
  const ServiceNotifier *service = nullptr;
  // A fault for tests: the render thread stops after taking this many
  // camera frames and hangs until the run is stopped, as one stuck in a
  // driver would (the output repeats the last composite meanwhile).
  std::optional<std::uint64_t> stall_render_after_frames;
  // A fault for tests: from this many camera frames on, every render says
  // the GPU was lost (FrameStatus::device_lost), as a device that fell off
  // its bus or was reset does; the outputs show the placeholder.
  std::optional<std::uint64_t> lose_gpu_after_frames;
  // Set (by SIGHUP) to reload the board from its file: the scene, the lens
  // profile, the render settings and a static pose are taken between two
  // frames, with no gap in the outputs; a board that does not load, or that
  // changes what takes a restart (run/board_reload.h), is refused with its
  // error on the status output and in systemd's STATUS=, and the run goes
  // on as it was. The run clears it when it starts a reload. Null: none.
  std::atomic<bool> *reload = nullptr;
  // The operator page (web/operator_page.h): served while the run goes,
  // from the web module, on its own thread; the frame loop only hands it
  // each frame's record and, while someone watches, a small preview.
  std::optional<web::WebOptions> web;
};

// What one output took.
struct OutputSummary {
  std::string name;          // "file camhead_sim.y4m"
  bool file = false;         // a file (errors are exit 4), else a device (exit 5)
  std::uint64_t written = 0; // frames it took
  std::uint64_t failed = 0;  // frames it did not (a full disk, a device gone)
  bool closed = true;        // finished: a file completed and put in place
  std::string detail;        // its last state or error
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
  std::uint64_t lens_late = 0;       // composites whose lens state did not cover their mid-exposure
  std::uint64_t reloads = 0;         // taken (RunOptions::reload)
  std::uint64_t reloads_refused = 0; // refused, the run going on as it was
  std::vector<OutputSummary> outputs;
  // Why the camera ended the run, if it broke off (a take played once with
  // a frame that cannot be read), naming the file and frame.
  std::string camera_failure;
  // Why the statistics file is not whole (a full disk); empty if it is.
  std::string stats_failure;
  // The first frame that could not be rendered, and why; empty if none.
  std::string render_failure;
  // A take composited offline: every camera frame was to be composited, so a
  // frame not rendered leaves it short.
  bool offline = false;
  double seconds = 0.0;
  std::string executor;
};

// The statistics file (--record-stats) cannot be opened or written.
class StatsFileError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// Sets everything up (throws std::runtime_error naming the board field,
// file or device at fault before any output is written: RunPathError when
// an output or the statistics file is one of the run's inputs or another
// output, StatsFileError when the statistics file cannot be opened), runs
// until `frames`, `duration_s`, `*stop` or the end of a take played once,
// and closes the outputs. What failed while running is in the summary.
RunSummary run_pipeline(const RunOptions &options);

} // namespace camhead::pipeline
