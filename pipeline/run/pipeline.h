// The live pipeline's run as one object, private to pipeline/run: opened
// whole before the first frame (pipeline_open.cpp), then run by three
// frame-loop threads, capture, render and output, with the status thread
// beside them (run_loop.cpp). run_loop.h is its public face.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camhead/base/bounded_queue.h"
#include "camhead/hal/camera/camera_source.h"
#include "camhead/hal/camera/frame_lease.h"
#include "camhead/hal/output/frame_sink.h"
#include "camhead/renderer/frame_renderer.h"
#include "config/board.h"
#include "frame_record.h"
#include "frame_setup.h"
#include "lens_hub.h"
#include "output_uri.h"
#include "run_counters.h"
#include "run_loop.h"
#include "run_status.h"
#include "setup_reloader.h"
#include "tracking/marker_source.h"
#include "tracking/pose_trace.h"
#include "web/operator_page.h"

namespace camhead::pipeline {

// One composite on its way to the outputs: a buffer per sink.
struct Slot {
  std::vector<std::vector<std::uint8_t>> images;
  FrameRecord record;
  // The pixels traced, for the operator page's region view (room for the
  // most a region holds, reserved once; kept only with a page).
  std::vector<renderer::PixelRect> region;
};

// A camera frame and when the camera handed it over. Dropped on any path,
// it gives the camera its buffer back (frame_lease.h).
struct Delivered {
  hal::camera::FrameLease frame;
  std::int64_t at_ns = 0;
};

constexpr int kSlots = 3; // frames between render and output
// How long a frame waits for the lens state of its mid-exposure while the
// source's readings are still coming: a live frame at most half its
// interval (the latency it adds), a take composited offline (nothing live
// waits on it) at most this long.
constexpr std::int64_t kOfflineLensWaitNs = 1'000'000'000;
inline std::int64_t lens_wait_ns(bool lossless, double fps) {
  return lossless ? kOfflineLensWaitNs : std::llround(0.5e9 / fps);
}

class Pipeline {
public:
  explicit Pipeline(const RunOptions &options);
  ~Pipeline();
  Pipeline(const Pipeline &) = delete;
  Pipeline &operator=(const Pipeline &) = delete;
  RunSummary run();

private:
  [[nodiscard]] bool should_stop() const;
  void capture_loop();
  void render_loop();
  void output_loop();
  // A reload's setup of `board`, its renderer made and prepared.
  std::unique_ptr<FrameSetup> build_setup(const Board &board) const;
  // Every pipeline and buffer `setup`'s renderer uses, made for the camera's
  // and the outputs' formats; the lens as it is now decides the kernels
  // (its model).
  void prepare(FrameSetup &setup) const;
  // The lens at the frame's mid-exposure; waits (bounded) for readings that
  // are on their way, and says how long in the record.
  LensSnapshot lens_at(std::int64_t mid_exposure_ns, FrameRecord &record);
  // The camera's pose at the frame's mid-exposure: a marker pose found in
  // the frame (waiting for the tracker as long as for the lens, at most),
  // a tracker's, or the static one.
  PoseSnapshot pose_at(std::uint64_t sequence, FrameRecord &record);
  // "static", "freed:NAME", "marker:NAME", "trace:FILE" for the record and
  // the status line.
  [[nodiscard]] std::string pose_source_name() const;
  RunSummary finish();
  // Sends one frame to every sink: `frame(i)` is sink i's, sent from where
  // it is (frame_sink.h).
  template <typename Frame> void send(Frame frame, std::int64_t capture_ns);

  const RunOptions &options_;
  // The board as the run started: what only a restart changes (the camera,
  // the outputs, the lens sources, the pose's kind, the executor).
  const Board &board_;
  // What frames are rendered with (the scene, the static pose, the render
  // settings, the renderer): the render thread's, replaced by reloads.
  std::unique_ptr<FrameSetup> setup_;
  // The outputs asked for, their paths checked beside the inputs' before
  // anything slow is opened (a simulated camera's warm-up takes seconds).
  std::vector<OutputSpec> output_specs_;
  SetupHandover handover_;
  LensHub lens_;
  std::unique_ptr<hal::camera::CameraSource> camera_;
  // A marker pose's tracker (null for any other pose): fed by the capture
  // thread, asked by the render thread.
  std::unique_ptr<MarkerPoseSource> markers_;
  // A trace pose's camera path.
  std::optional<PoseTrace> pose_trace_;
  double fps_ = 25.0;
  std::vector<std::unique_ptr<hal::output::FrameSink>> sinks_;
  std::vector<bool> file_sinks_;           // which sinks are files (their errors: exit 4)
  std::vector<std::uint64_t> sink_failed_; // output thread: frames each sink did not take
  std::FILE *stats_ = nullptr;
  std::string executor_name_;
  RunRecordFields record_fields_; // the record's fields that every frame shares

  std::vector<Slot> slots_{kSlots};
  std::vector<std::vector<std::uint8_t>> last_frames_;  // what each sink showed last
  std::vector<std::vector<std::uint8_t>> placeholders_; // each sink's, made once
  // Render thread: where a frame's composite goes, its slot's buffers
  // (named anew each frame: the output thread swaps them).
  std::vector<renderer::VideoBuffer> targets_;
  std::string camera_failure_; // capture thread; read after it is joined
  std::string render_failure_; // render thread: the first; after the join
  base::BoundedQueue<int> free_slots_{kSlots}, ready_slots_{kSlots};
  base::BoundedQueue<Delivered> captured_{1};
  RunCounters counters_;
  // The reload thread's (RunOptions::reload); none without reloads.
  std::optional<SetupReloader> reloader_;
  std::optional<RunStatus> status_; // the status line, unless options_.status is null
  std::atomic<bool> stopping_{false};
  // A camera that waits for its consumer (a file not played in real time):
  // the capture thread waits for the renderer instead of replacing frames.
  bool lossless_ = false;
  std::int64_t start_ns_ = 0;
  std::int64_t last_output_ns_ = 0;           // output thread only
  std::optional<std::size_t> recording_sink_; // the output whose frames the page records
  // The operator page, if asked for; last, so that its server (which reads
  // the members above) stops first.
  std::unique_ptr<web::OperatorPage> page_;
};

} // namespace camhead::pipeline
