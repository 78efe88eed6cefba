#include "run_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <thread>
#include <utility>

#include <glm/geometric.hpp>

#include "camhead/base/bounded_queue.h"
#include "camhead/base/monotonic_clock.h"
#include "camhead/base/thread_name.h"
#include "camhead/hal/camera/camera_source.h"
#include "camhead/hal/camera/frame_lease.h"
#include "camhead/hal/output/frame_sink.h"
#include "camhead/renderer/frame_budget.h"
#include "camhead/renderer/frame_renderer.h"
#include "frame_record.h"
#include "frame_setup.h"
#include "lens_camera.h"
#include "lens_hub.h"
#include "pipeline.h"
#include "run_status.h"
#include "setup_reloader.h"
#include "status_thread.h"
#include "tracking/marker_source.h"
#include "tracking/pose_trace.h"
#include "web/operator_page.h"

namespace camhead::pipeline {
namespace {

using namespace std::chrono_literals;
using hal::camera::CapturedFrame;
using hal::camera::CaptureResult;
using hal::output::FrameSink;

// A camera without a frame for this long (or four frame intervals, if
// longer) counts as lost, whatever it says.
constexpr std::int64_t kCameraSilentNs = 1'000'000'000;

} // namespace

bool Pipeline::should_stop() const {
  if (stopping_ || (options_.stop != nullptr && *options_.stop))
    return true;
  if (options_.duration_s > 0.0 &&
      double(base::monotonic_ns() - start_ns_) * 1e-9 >= options_.duration_s)
    return true;
  return options_.frames > 0 && counters_.frames_out >= options_.frames;
}

void Pipeline::capture_loop() {
  // A camera that goes silent without saying it is gone (a capture card that
  // lost its signal, a libcamera sensor that stopped) is lost as well: the
  // outputs show the placeholder, not its last frame forever.
  // Silence counts from the first frame: a camera still starting is not
  // lost (the outputs show the placeholder until it sends anyway).
  const std::int64_t silent_after_ns =
      std::max<std::int64_t>(kCameraSilentNs, std::llround(4e9 / fps_));
  std::optional<std::int64_t> last_frame_ns;
  while (!should_stop()) {
    CapturedFrame frame;
    const CaptureResult result = camera_->wait_frame(100ms, frame);
    const std::int64_t now = base::monotonic_ns();
    if (result == CaptureResult::frame)
      last_frame_ns = now;
    counters_.camera_lost = result == CaptureResult::disconnected ||
                            (!lossless_ && last_frame_ns && now - *last_frame_ns > silent_after_ns);
    if (result == CaptureResult::failed)
      camera_failure_ = camera_->status().detail;
    if (result == CaptureResult::ended || result == CaptureResult::failed) {
      stopping_ = true;
      break;
    }
    if (result != CaptureResult::frame)
      continue;
    ++counters_.frames_in;
    if (markers_)
      markers_->submit(frame); // tracked while the frame before renders
    Delivered delivered{{*camera_, frame}, base::monotonic_ns()};
    if (lossless_) {
      // A file played as fast as it is taken: every frame is rendered (a
      // frame refused by a closed queue goes back as its lease ends).
      (void)captured_.push_waiting(std::move(delivered));
    } else if (captured_.push(std::move(delivered))) {
      ++counters_.render_busy; // the one it replaced has gone back
    }
  }
  captured_.close();
}

void Pipeline::render_loop() {
  renderer::FrameBudget budget(frame_budget_settings(setup_->board.render, fps_));
  std::optional<std::uint64_t> last_sequence;
  std::uint64_t rendered = 0;
  for (;;) {
    if (options_.stall_render_after_frames && rendered >= *options_.stall_render_after_frames) {
      while (!should_stop()) // stuck, as in a driver that never returns
        std::this_thread::sleep_for(10ms);
      break;
    }
    // A reload's setup, between two frames (and while no camera sends).
    if (handover_.take(setup_))
      budget = renderer::FrameBudget(frame_budget_settings(setup_->board.render, fps_));
    std::optional<Delivered> delivered = captured_.pop(100ms);
    if (!delivered) {
      if (captured_.drained())
        break;
      continue;
    }
    ++rendered;
    const CapturedFrame &frame = delivered->frame.frame();
    std::optional<int> slot_index = free_slots_.pop(200ms);
    while (lossless_ && !slot_index && !free_slots_.closed())
      slot_index = free_slots_.pop(200ms);
    if (!slot_index) {
      ++counters_.output_busy;
      continue; // the frame goes back with its lease
    }
    Slot &slot = slots_[std::size_t(*slot_index)];
    FrameRecord &r = slot.record;
    r = {};
    r.sequence = frame.sequence;
    r.setup = setup_->generation;
    r.capture_ns = frame.timestamp_ns;
    r.exposure_mid_ns = hal::camera::mid_exposure_ns(frame);
    r.delivered_ns = delivered->at_ns;
    // The camera frames since the last one rendered that will never be
    // output: lost by the camera, replaced while this thread was busy, or
    // without an output slot.
    r.dropped_before = last_sequence ? frame.sequence - *last_sequence - 1 : frame.sequence;
    last_sequence = frame.sequence;

    const LensSnapshot lens = lens_at(r.exposure_mid_ns, r);
    r.focus_m = lens.state.focus_distance_m.value;
    r.f_number = lens.state.f_number.value;
    r.focal_length_mm = lens.state.focal_length_mm.value;
    r.lens_fresh = lens.fresh;
    const PoseSnapshot pose = pose_at(frame.sequence, r);
    const renderer::FrameCamera posed = markers_ || pose_trace_ || lens_.tracks_pose()
                                            ? placed(setup_->base_camera, pose.pose)
                                            : setup_->base_camera;
    r.pose_fresh = pose.fresh;
    r.pose_known = pose.known;
    counters_.pose_stale = !pose.fresh;
    counters_.pose_unknown = !pose.known;
    r.position = posed.position;
    r.forward = glm::normalize(posed.look_at - posed.position);
    r.up = posed.up;
    renderer::FrameRequest request = setup_request(*setup_, options_.influence_region);
    request.camera = lens_camera(posed, lens.state);
    if (setup_->board.render.rays_per_pixel)
      request.rays_per_pixel = *setup_->board.render.rays_per_pixel;
    else
      renderer::set_mean_rays_per_pixel(request, budget.rays_per_pixel());
    request.seed = std::uint32_t(frame.sequence * 2654435761u) | 1u;
    // Before the pose source's first pose, virtual objects drawn from the
    // stand-in (the scene's camera) would stand wherever that puts them (on
    // the moving rig, 1200 px off): the frame goes out as the camera image
    // alone.
    request.plate_only = !pose.known;
    r.rpp = request.rays_per_pixel + double(request.extra_rays_per_pixel);

    for (std::size_t i = 0; i < sinks_.size(); ++i)
      targets_[i] = {sinks_[i]->format(), slot.images[i]};
    r.render_start_ns = base::monotonic_ns();
    renderer::FrameReport report =
        setup_->renderer->render(request, {frame.format, frame.bytes}, targets_);
    if (options_.lose_gpu_after_frames && rendered > *options_.lose_gpu_after_frames) {
      report.status = renderer::FrameStatus::device_lost;
      report.detail = "the GPU was lost (a fault for tests)";
    }
    r.render_end_ns = base::monotonic_ns();
    if (page_)
      page_->feed().camera(frame.sequence, frame.format, frame.bytes);
    delivered->frame.reset(); // the camera may fill the buffer again
    if (report.status != renderer::FrameStatus::ok) {
      ++counters_.render_failed;
      if (render_failure_.empty())
        render_failure_ = report.detail;
      if (report.status == renderer::FrameStatus::device_lost)
        counters_.renderer_lost = true;
      (void)free_slots_.push(*slot_index);
      continue;
    }
    if (page_) // within the room reserved (max_region_rects): no allocation
      slot.region.assign(report.region.begin(),
                         report.region.begin() + std::ptrdiff_t(std::min(report.region.size(),
                                                                         slot.region.capacity())));
    r.camera_rays = report.camera_rays;
    r.traced = report.frame_pixels > 0 ? double(report.traced_pixels) / report.frame_pixels : 1.0;
    counters_.traced_permille = std::uint32_t(std::lround(1000.0 * r.traced));
    r.decode_s = report.decode_s;
    r.trace_s = report.trace_s;
    r.rays_s = report.rays_s;
    r.encode_s = report.encode_s;
    r.history_samples = report.history_samples;
    r.reprojected_samples = report.reprojected_samples;
    // What the frame cost for the rays it traced, a mean (adaptive and
    // accumulating frames share them unevenly; a full history traces none).
    budget.measured(report.traced_pixels > 0 ? double(report.camera_rays) / report.traced_pixels
                                             : 0.0,
                    report.decode_s + report.trace_s + report.encode_s, report.rays_s);
    counters_.rpp = r.rpp;
    (void)ready_slots_.push(*slot_index);
  }
  ready_slots_.close();
}

LensSnapshot Pipeline::lens_at(std::int64_t mid_exposure_ns, FrameRecord &record) {
  // A frame waits for the readings that cover it (LensHub::state_when_covered).
  // A stop asked for by the user ends the wait; a take played to its end
  // does not (its last frames still get their lens).
  const std::int64_t start = base::monotonic_ns();
  const LensSnapshot lens = lens_.state_when_covered(
      mid_exposure_ns, start + lens_wait_ns(lossless_, fps_), options_.stop);
  record.lens_wait_s = double(base::monotonic_ns() - start) * 1e-9;
  if (!lens.fresh)
    ++counters_.lens_late;
  return lens;
}

std::string Pipeline::pose_source_name() const {
  if (markers_)
    return markers_->name();
  if (pose_trace_)
    return "trace:" + board_.pose->file.filename().string();
  return lens_.pose_source();
}

PoseSnapshot Pipeline::pose_at(std::uint64_t sequence, FrameRecord &record) {
  if (pose_trace_)
    return {pose_trace_->at(record.exposure_mid_ns), true, true};
  if (!markers_)
    return lens_.pose_at(record.exposure_mid_ns, setup_->rest_pose);
  const std::int64_t deadline = record.delivered_ns + lens_wait_ns(lossless_, fps_);
  const FramePose found =
      markers_->pose_for(sequence, record.exposure_mid_ns, deadline, setup_->rest_pose);
  record.markers_seen = found.markers_seen;
  record.reprojection_px = found.reprojection_px;
  record.pose_found_by = found.found_by;
  record.track_s = found.track_s;
  record.pose_wait_s = found.wait_s;
  return {found.pose, found.fresh, found.known};
}

template <typename Frame> void Pipeline::send(Frame frame, std::int64_t capture_ns) {
  for (std::size_t i = 0; i < sinks_.size(); ++i)
    if (!sinks_[i]->submit(frame(i), capture_ns)) {
      ++counters_.sink_errors;
      ++sink_failed_[i];
    }
  last_output_ns_ = base::monotonic_ns();
}

void Pipeline::output_loop() {
  const std::int64_t repeat_after_ns = std::llround(options_.repeat_after_s * 1e9);
  // Awake at least as often as a filler may be due.
  const auto wait =
      std::min<std::chrono::nanoseconds>(100ms, std::chrono::nanoseconds(repeat_after_ns));
  last_output_ns_ = base::monotonic_ns();
  bool shown_any = false;
  std::uint64_t output_frame = 0; // frames sent to every output so far
  for (;;) {
    const std::optional<int> slot_index = ready_slots_.pop(wait);
    if (!slot_index) {
      if (ready_slots_.drained())
        break;
      // A take composited offline gets its composites alone, and a run that
      // is stopping no more frames.
      if (lossless_ || should_stop() || base::monotonic_ns() - last_output_ns_ < repeat_after_ns)
        continue;
      const bool repeat = shown_any && !counters_.camera_lost && !counters_.renderer_lost;
      if (repeat) {
        send([&](std::size_t i) { return std::span(last_frames_[i]); }, base::monotonic_ns());
        ++counters_.repeats;
      } else {
        send([&](std::size_t i) { return std::span(placeholders_[i]); }, base::monotonic_ns());
        ++counters_.placeholders;
      }
      if (stats_ != nullptr)
        write_filler_record(stats_, output_frame, repeat ? "repeat" : "placeholder",
                            last_output_ns_);
      if (page_) {
        page_->feed().filler(
            output_frame, repeat ? web::FeedEntry::Kind::repeat : web::FeedEntry::Kind::placeholder,
            last_output_ns_);
        if (recording_sink_) // a take keeps the outputs' time, fillers included
          page_->recorder().submit(repeat ? last_frames_[*recording_sink_]
                                          : placeholders_[*recording_sink_],
                                   last_output_ns_);
      }
      ++output_frame;
      continue;
    }
    Slot &slot = slots_[std::size_t(*slot_index)];
    if (options_.frames > 0 && counters_.frames_out >= options_.frames) {
      (void)free_slots_.push(*slot_index); // rendered after the last one asked for
      continue;
    }
    send([&](std::size_t i) { return std::span(slot.images[i]); }, slot.record.capture_ns);
    counters_.latency_ns = last_output_ns_ - slot.record.capture_ns;
    if (stats_ != nullptr)
      write_composite_record(stats_, output_frame, slot.record, last_output_ns_, record_fields_);
    if (page_) {
      page_->feed().composite(output_frame, slot.record, last_output_ns_, slot.images.front(),
                              slot.region);
      if (recording_sink_)
        page_->recorder().submit(slot.images[*recording_sink_], slot.record.capture_ns);
    }
    ++output_frame;
    for (std::size_t i = 0; i < sinks_.size(); ++i)
      last_frames_[i].swap(slot.images[i]); // the slot takes the older buffer
    shown_any = true;
    ++counters_.frames_out;
    (void)free_slots_.push(*slot_index);
  }
}

RunSummary Pipeline::run() {
  start_ns_ = base::monotonic_ns();
  std::vector<std::thread> threads;
  try {
    if (reloader_) {
      threads.emplace_back([this, live = setup_->board]() mutable {
        base::name_this_thread("camhead-reload");
        reloader_->run(std::move(live));
      });
    }
    threads.emplace_back([this] {
      base::name_this_thread("camhead-capture");
      capture_loop();
    });
    threads.emplace_back([this] {
      base::name_this_thread("camhead-render");
      render_loop();
    });
    threads.emplace_back([this] {
      base::name_this_thread("camhead-output");
      output_loop();
    });
  } catch (...) {
    // A thread that cannot start: stop the ones that did (a capture thread
    // waiting for room, a render thread for a slot), then say so.
    stopping_ = true;
    captured_.close();
    free_slots_.close();
    ready_slots_.close();
    for (std::thread &thread : threads)
      thread.join();
    throw;
  }
  run_status_thread(
      status_ ? &*status_ : nullptr, options_.service, counters_, reloader_ ? &*reloader_ : nullptr,
      start_ns_, [this] { return should_stop() || (captured_.closed() && ready_slots_.closed()); });
  stopping_ = true;
  for (std::thread &thread : threads)
    thread.join();
  return finish();
}

RunSummary Pipeline::finish() {
  RunSummary summary;
  if (status_)
    status_->report_sink_errors(); // those of the last second
  for (std::size_t i = 0; i < sinks_.size(); ++i) {
    FrameSink &sink = *sinks_[i];
    const bool closed = sink.close();
    if (!closed)
      ++summary.sink_errors;
    const hal::output::SinkStatus status = sink.status();
    summary.outputs.push_back(
        {sink.name(), file_sinks_[i], status.frames, sink_failed_[i], closed, status.detail});
  }
  // Closed once, here or (after a failed run) by the destructor.
  if (std::FILE *stats = std::exchange(stats_, nullptr); stats != nullptr) {
    // A failed write mid-run shows in ferror(), the last one in fclose().
    const bool written = std::ferror(stats) == 0;
    if (std::fclose(stats) != 0 || !written)
      summary.stats_failure =
          options_.stats_file->string() + ": not all of the statistics were written (a full disk?)";
  }
  summary.camera_failure = camera_failure_;
  summary.render_failure = render_failure_;
  summary.offline = lossless_;
  summary.lens_late = counters_.lens_late;
  const hal::camera::CameraStatus cam = camera_->status();
  summary.frames_in = counters_.frames_in;
  summary.frames_out = counters_.frames_out;
  summary.camera_dropped = cam.dropped;
  summary.camera_errors = cam.errors;
  summary.camera_reconnects = cam.reconnects;
  summary.render_busy = counters_.render_busy;
  summary.output_busy = counters_.output_busy;
  summary.render_failed = counters_.render_failed;
  summary.placeholders = counters_.placeholders;
  summary.repeats = counters_.repeats;
  summary.reloads = reloader_ ? reloader_->reloads() : 0;
  summary.reloads_refused = reloader_ ? reloader_->refused() : 0;
  summary.sink_errors += counters_.sink_errors;
  summary.seconds = double(base::monotonic_ns() - start_ns_) * 1e-9;
  summary.executor = executor_name_;
  return summary;
}

RunSummary run_pipeline(const RunOptions &options) {
  Pipeline pipeline(options);
  return pipeline.run();
}

} // namespace camhead::pipeline
