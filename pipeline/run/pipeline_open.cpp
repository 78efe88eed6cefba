// Opening a run: everything that can fail, before the first frame.
#include <cerrno>
#include <cstring>
#include <utility>
#include <variant>

#include "camhead/base/monotonic_clock.h"
#include "lens_camera.h"
#include "pipeline.h"
#include "placeholder.h"
#include "rig_setup.h"
#include "run_paths.h"
#include "status_thread.h"

namespace camhead::pipeline {
namespace {

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

} // namespace

// Everything that can fail is opened here, before the first frame: the
// outputs' names and every path checked first (before a simulated camera's
// warm-up), the outputs opened last (a file output is only created once the
// rest stands). The camera comes before the renderer: a take's size is
// checked against the board before anything of that size is allocated.
Pipeline::Pipeline(const RunOptions &options)
    : options_(options), board_(checked_board(options)), setup_(load_frame_setup(board_)),
      output_specs_(checked_outputs(options, setup_->scene)), lens_(board_),
      camera_(open_camera(board_, setup_->scene, setup_->base_camera, lens_, options.threads,
                          {options.frames, options.duration_s})),
      markers_(open_marker_source(
          board_, camera_->format(), setup_->base_camera, lens_, offline_take(board_),
          lens_wait_ns(offline_take(board_), camera_fps(*camera_)), camera_fps(*camera_))),
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
                     .lens_profile = board_.lens.profile.value_or(std::filesystem::path()),
                     .sensor_width_mm = board_.camera->sensor_width_mm},
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

} // namespace camhead::pipeline
