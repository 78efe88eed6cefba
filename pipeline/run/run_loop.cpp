#include "run_loop.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <utility>
#include <variant>

#include <glm/geometric.hpp>

#include "camhead/base/bounded_queue.h"
#include "camhead/base/monotonic_clock.h"
#include "camhead/base/thread_name.h"
#include "camhead/hal/camera/camera_source.h"
#include "camhead/hal/camera/frame_lease.h"
#include "camhead/hal/output/frame_sink.h"
#include "camhead/renderer/frame_budget.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/influence_region.h"
#include "frame_record.h"
#include "frame_setup.h"
#include "lens_camera.h"
#include "lens_hub.h"
#include "output_uri.h"
#include "placeholder.h"
#include "rig_setup.h"
#include "run_paths.h"
#include "run_status.h"
#include "setup_reloader.h"
#include "status_thread.h"
#include "tracking/camera_pose.h"
#include "tracking/marker_source.h"
#include "tracking/pose_trace.h"
#include "web/operator_page.h"

namespace camhead::pipeline {
namespace {

using namespace std::chrono_literals;
using hal::camera::CameraSource;
using hal::camera::CapturedFrame;
using hal::camera::CaptureResult;
using hal::output::FrameSink;

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

// A camera without a frame for this long (or four frame intervals, if
// longer) counts as lost, whatever it says.
constexpr std::int64_t kCameraSilentNs = 1'000'000'000;
constexpr int kSlots = 3; // frames between render and output
// How long a frame waits for the lens state of its mid-exposure while the
// source's readings are still coming: a live frame at most half its
// interval (the latency it adds), a take composited offline (nothing live
// waits on it) at most this long.
constexpr std::int64_t kOfflineLensWaitNs = 1'000'000'000;
std::int64_t lens_wait_ns(bool lossless, double fps) {
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
  std::unique_ptr<CameraSource> camera_;
  // A marker pose's tracker (null for any other pose): fed by the capture
  // thread, asked by the render thread.
  std::unique_ptr<MarkerPoseSource> markers_;
  // A trace pose's camera path.
  std::optional<PoseTrace> pose_trace_;
  double fps_ = 25.0;
  std::vector<std::unique_ptr<FrameSink>> sinks_;
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

// The run's outputs, and every path it reads or writes checked.
std::vector<OutputSpec> checked_outputs(const RunOptions &options, const renderer::Scene &scene) {
  std::vector<OutputSpec> specs =
      parse_output_uris(options.outputs.empty() ? options.board.outputs : options.outputs);
  if (specs.empty())
    throw OutputError(options.board.file.string(),
                      "no output: give --output URI, or \"outputs\" in the board");
  std::vector<RunPath> paths = run_inputs(options.board, scene);
  for (RunPath &output : run_outputs(specs))
    paths.push_back(std::move(output));
  if (options.stats_file)
    paths.push_back({"--record-stats", *options.stats_file, true, false});
  check_run_paths(paths);
  return specs;
}

// A take played as fast as it is composited (a file, or the simulated
// world, not in real time): every frame is rendered.
bool offline_take(const Board &board) {
  if (const auto *file = std::get_if<FileCameraConfig>(&board.camera->kind))
    return !file->realtime;
  if (const auto *sim = std::get_if<SimCameraConfig>(&board.camera->kind))
    return !sim->realtime;
  return false;
}

const Board &checked_board(const RunOptions &options) {
  if (!options.board.camera)
    throw std::runtime_error(options.board.file.string() +
                             ": camera: missing: this board has no camera for `camhead run`");
  return options.board;
}

// Everything that can fail is opened here, before the first frame: the
// outputs' names and every path checked first (before a simulated camera's
// warm-up), the outputs opened last (a file output is only created once the
// rest stands). The
// camera comes before the renderer: a take's size is checked against the
// board before anything of that size is allocated.
Pipeline::Pipeline(const RunOptions &options)
    : options_(options), board_(checked_board(options)), setup_(load_frame_setup(board_)),
      output_specs_(checked_outputs(options, setup_->scene)), lens_(board_),
      camera_(open_camera(board_, setup_->scene, setup_->base_camera, lens_, options.threads,
                          {options.frames, options.duration_s})),
      markers_(open_marker_source(board_, camera_->format(), setup_->base_camera, lens_,
                                  offline_take(board_),
                                  lens_wait_ns(offline_take(board_), camera_fps(*camera_)))),
      pose_trace_(board_.pose && board_.pose->type == PoseType::trace
                      ? std::optional<PoseTrace>(load_pose_trace(board_.pose->file))
                      : std::nullopt),
      fps_(camera_fps(*camera_)) {
  setup_->renderer = make_renderer(board_, options.executor.value_or(board_.render.executor),
                                   setup_->scene, options.threads);
  executor_name_ = setup_->renderer->executor();
  record_fields_ = {json_string(executor_name_), json_string(pose_source_name())};
  for (const OutputSpec &spec : output_specs_) {
    sinks_.push_back(open_output(spec, board_.camera->width, board_.camera->height, fps_));
    file_sinks_.push_back(spec.kind == OutputKind::y4m || spec.kind == OutputKind::png);
  }
  if (options.stats_file) {
    // A stream of records, written as the run goes (for `tail -f`, or into
    // a FIFO or /dev/stdout on purpose), not a partial file renamed at the
    // end as camhead's other files are.
    stats_ = std::fopen(options.stats_file->c_str(), "w");
    if (stats_ == nullptr)
      throw StatsFileError(options.stats_file->string() +
                           ": cannot be written: " + std::strerror(errno));
  }
  // Every pipeline and buffer the loop uses, made now.
  prepare(*setup_);
  for (Slot &slot : slots_) {
    for (const auto &sink : sinks_)
      slot.images.emplace_back(base::frame_bytes(sink->format()));
    if (options.web)
      slot.region.reserve(renderer::max_region_rects(std::uint32_t(board_.camera->width),
                                                     std::uint32_t(board_.camera->height)));
  }
  for (const auto &sink : sinks_) {
    last_frames_.emplace_back(base::frame_bytes(sink->format()));
    fill_placeholder(sink->format(), placeholders_.emplace_back(last_frames_.back().size()));
  }
  targets_.resize(sinks_.size());
  sink_failed_.assign(sinks_.size(), 0);
  for (int i = 0; i < kSlots; ++i)
    (void)free_slots_.push(i);
  lossless_ = offline_take(board_);
  if (options.status != nullptr)
    status_.emplace(options.status, *camera_, lens_, sinks_, counters_, executor_name_,
                    pose_source_name());
  if (options.reload != nullptr)
    reloader_.emplace(
        *options.reload, options.service, handover_, lens_,
        [this](const Board &board) { return build_setup(board); },
        [this] { return should_stop(); });
  if (options.web) {
    // The page's takes are Y4M, of the first output in a format it takes.
    for (std::size_t i = 0; i < sinks_.size() && !recording_sink_; ++i)
      if (const base::PixelFormat f = sinks_[i]->format().pixel;
          f == base::PixelFormat::yuyv || f == base::PixelFormat::nv12)
        recording_sink_ = i;
    const bool marker_pose = board_.pose && board_.pose->type == PoseType::marker;
    page_ = std::make_unique<web::OperatorPage>(
        *options.web,
        web::RunView{.board_name = board_.name,
                     .board_file = board_.file.string(),
                     .board_description = board_.description,
                     .camera = *camera_,
                     .lens = lens_,
                     .sinks = sinks_,
                     .counters = counters_,
                     .executor = executor_name_,
                     .pose_source = pose_source_name(),
                     .fps = fps_,
                     .reloader = reloader_ ? &*reloader_ : nullptr,
                     .record_format = recording_sink_
                                          ? std::optional(sinks_[*recording_sink_]->format())
                                          : std::nullopt,
                     .marker_board = marker_pose ? board_.pose->file : std::filesystem::path(),
                     .lens_profile = board_.lens.profile.value_or(std::filesystem::path())},
        sinks_.front()->format(), camera_->format());
    if (options.status != nullptr)
      std::fprintf(options.status, "camhead run: operator page at %s\n", page_->url().c_str());
  }
  if (markers_)
    markers_->start();
  // Last: a trace played from the rig's start starts with the run, not a
  // set-up's time (a renderer's kernel compiles) before its first frame.
  lens_.start();
}

Pipeline::~Pipeline() {
  if (stats_ != nullptr)
    std::fclose(stats_); // a run that failed: what was recorded stays
}

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
    counters_.pose_stale = !pose.fresh;
    r.position = posed.position;
    r.forward = glm::normalize(posed.look_at - posed.position);
    r.up = posed.up;
    renderer::FrameRequest request = setup_request(*setup_, options_.influence_region);
    request.camera = lens_camera(posed, lens.state);
    request.rays_per_pixel = setup_->board.render.rays_per_pixel.value_or(budget.rpp());
    request.seed = std::uint32_t(frame.sequence * 2654435761u) | 1u;
    r.rpp = request.rays_per_pixel;

    for (std::size_t i = 0; i < sinks_.size(); ++i)
      targets_[i] = {sinks_[i]->format(), slot.images[i]};
    r.render_start_ns = base::monotonic_ns();
    const renderer::FrameReport report =
        setup_->renderer->render(request, {frame.format, frame.bytes}, targets_);
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
    r.encode_s = report.encode_s;
    r.history_samples = report.history_samples;
    r.reprojected_samples = report.reprojected_samples;
    // What the frame cost for the rays it traced, a mean (adaptive and
    // accumulating frames share them unevenly; a full history traces none).
    budget.measured(report.traced_pixels > 0 ? double(report.camera_rays) / report.traced_pixels
                                             : 0.0,
                    report.decode_s + report.trace_s + report.encode_s);
    counters_.rpp = request.rays_per_pixel;
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
    return {pose_trace_->at(record.exposure_mid_ns), true};
  if (!markers_)
    return lens_.pose_at(record.exposure_mid_ns, setup_->rest_pose);
  const std::int64_t deadline = record.delivered_ns + lens_wait_ns(lossless_, fps_);
  const FramePose found =
      markers_->pose_for(sequence, record.exposure_mid_ns, deadline, setup_->rest_pose);
  record.markers_seen = found.markers_seen;
  record.reprojection_px = found.reprojection_px;
  record.track_s = found.track_s;
  record.pose_wait_s = found.wait_s;
  return {found.pose, found.fresh};
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

std::unique_ptr<FrameSetup> Pipeline::build_setup(const Board &board) const {
  std::unique_ptr<FrameSetup> setup = load_frame_setup(board);
  setup->renderer = make_renderer(setup->board, options_.executor.value_or(board_.render.executor),
                                  setup->scene, options_.threads);
  prepare(*setup);
  return setup;
}

void Pipeline::prepare(FrameSetup &setup) const {
  std::vector<base::VideoFormat> formats;
  for (const auto &sink : sinks_)
    formats.push_back(sink->format());
  renderer::FrameRequest first = setup_request(setup, options_.influence_region);
  first.camera = lens_camera(setup.base_camera, lens_.state_at(base::monotonic_ns()).state);
  setup.renderer->prepare(first, camera_->format(), formats);
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

} // namespace

RunSummary run_pipeline(const RunOptions &options) {
  Pipeline pipeline(options);
  return pipeline.run();
}

} // namespace camhead::pipeline
