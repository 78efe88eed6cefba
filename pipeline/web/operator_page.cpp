#include "operator_page.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <thread>

#include <nlohmann/json.hpp>

#include "calibration_marks.h"
#include "camera_views.h"
#include "camhead/base/monotonic_clock.h"
#include "camhead/lens_control/lens_profile.h"
#include "tracking/luma.h"
#include "tracking/marker_board.h"
#include "web_server.h"

namespace camhead::pipeline::web {
namespace {

using nlohmann::json;

web_module::ServerConfig server_config(const WebOptions &options) {
  web_module::ServerConfig config;
  config.host = options.listen.host;
  config.port = options.listen.port;
  if (options.password_file) {
    config.password_hash = read_password_file(*options.password_file);
  } else if (!is_loopback(options.listen.host)) {
    throw WebAccessError(
        "--http " + options.listen.host + ":" + std::to_string(options.listen.port) +
        ": an address other machines reach needs a password: give --http-password FILE "
        "(`camhead web-password FILE` sets one), or listen on 127.0.0.1");
  }
  return config;
}

// A JSON number, or null for a value that is none (NaN: no marker seen).
json number(double value) {
  return std::isfinite(value) ? json(value) : json(nullptr);
}

json vec(const glm::vec3 &v) {
  return json::array({v.x, v.y, v.z});
}

// A Prometheus label value: backslash, quote and newline escaped.
std::string label(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '\\' || c == '"')
      out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

class Metrics {
public:
  // A family's help and type lines, once.
  void family(const char *name, const char *type, const char *help) {
    out_ += std::string("# HELP ") + name + " " + help + "\n# TYPE " + name + " " + type + "\n";
  }
  void sample(const std::string &name_and_labels, double value) {
    char text[64];
    if (std::isnan(value))
      std::snprintf(text, sizeof text, "NaN");
    else
      std::snprintf(text, sizeof text, "%.9g", value);
    out_ += name_and_labels + " " + text + "\n";
  }
  void one(const char *name, const char *type, const char *help, double value) {
    family(name, type, help);
    sample(name, value);
  }
  std::string take() { return std::move(out_); }

private:
  std::string out_;
};

} // namespace

OperatorPage::OperatorPage(const WebOptions &options, RunView run,
                           const base::VideoFormat &composite, const base::VideoFormat &camera)
    : run_(std::move(run)),
      feed_(composite, camera), previews_{preview_for(composite), preview_for(camera),
                                          preview_for(composite)},
      recorder_(options.recordings, run_.record_format, run_.fps), recordings_(options.recordings),
      marks_file_(options.recordings / "lens-marks.csv"), start_ns_(base::monotonic_ns()) {
  server_ = start_web_server(server_config(options), *this);
}

OperatorPage::~OperatorPage() {
  server_.reset(); // no call from the server's thread after this
}

std::string OperatorPage::url() const {
  return server_->url();
}

void OperatorPage::watch(View view, int delta) {
  feed_.watch(view, delta);
}

const PreviewImage &OperatorPage::preview(View view) {
  PreviewImage &preview = previews_[int(view)];
  if (!frozen_ && feed_.take_frame(view)) {
    const FrameCopy &frame = feed_.frame(view);
    shrink_to_preview(frame.format, frame.bytes, preview);
    if (view == View::region)
      shade_outside(frame.region(), frame.format.width, frame.format.height, preview);
    preview.frame = frame.frame;
  }
  return preview;
}

void OperatorPage::drain() {
  while (const std::optional<FeedEntry> entry = feed_.next_entry())
    history_.add(*entry);
  // The camera's count, sampled at most ten times a second, for ten seconds.
  const std::int64_t now = base::monotonic_ns();
  if (in_samples_.empty() || now - in_samples_.back().first >= 100'000'000)
    in_samples_.emplace_back(now, run_.counters.frames_in.load());
  while (in_samples_.size() > 2 && now - in_samples_.front().first > 10'000'000'000)
    in_samples_.pop_front();
}

std::string OperatorPage::state_json(const web_module::HttpStats &http) {
  drain();
  const RunCounters &c = run_.counters;
  const std::int64_t now = base::monotonic_ns();
  json state;
  state["version"] = CAMHEAD_VERSION;
  state["uptime_s"] = double(now - start_ns_) * 1e-9;
  state["board"] = {{"name", run_.board_name},
                    {"file", run_.board_file},
                    {"description", run_.board_description}};
  state["executor"] = run_.executor;
  state["frozen"] = frozen_;
  state["can_reload"] = run_.reloader != nullptr;
  if (run_.reloader != nullptr) {
    const SetupReloader::Outcome reload = run_.reloader->last_outcome();
    state["reload"] = {{"outcomes", reload.count}, {"last", reload.text}};
  } else {
    state["reload"] = nullptr;
  }
  state["can_record"] = run_.record_format.has_value();
  if (const auto take = recorder_.file())
    state["recording"] = {{"file", take->string()}, {"frames", recorder_.frames()}};
  else
    state["recording"] = nullptr;

  const hal::camera::CameraStatus camera = run_.camera.status();
  state["camera"] = {{"name", run_.camera.name()},
                     {"format", base::describe(run_.camera.format())},
                     {"fps", run_.fps},
                     {"connected", camera.connected && !c.camera_lost},
                     {"frames", camera.frames},
                     {"dropped", camera.dropped},
                     {"errors", camera.errors},
                     {"reconnects", camera.reconnects},
                     {"detail", camera.detail}};
  json outputs = json::array();
  for (const auto &sink : run_.sinks) {
    const hal::output::SinkStatus status = sink->status();
    outputs.push_back({{"name", sink->name()},
                       {"format", base::describe(sink->format())},
                       {"connected", status.connected},
                       {"frames", status.frames},
                       {"errors", status.errors},
                       {"detail", status.detail}});
  }
  state["outputs"] = outputs;

  const LensSnapshot lens = run_.lens.state_at(now);
  const std::optional<hal::lens::EncoderReading> reading = run_.lens.last_reading();
  const auto counts = [&](std::optional<std::int32_t> hal::lens::EncoderReading::*axis) {
    if (!reading)
      return json(nullptr);
    const std::optional<std::int32_t> &value = (*reading).*axis;
    return value ? json(*value) : json(nullptr);
  };
  state["lens"] = {{"source", run_.lens.source_name()},
                   {"counts",
                    {{"focus", counts(&hal::lens::EncoderReading::focus)},
                     {"iris", counts(&hal::lens::EncoderReading::iris)},
                     {"zoom", counts(&hal::lens::EncoderReading::zoom)}}},
                   {"connected", lens.connected},
                   {"fresh", lens.fresh},
                   {"focus_m", lens.state.focus_distance_m.value},
                   {"f_number", lens.state.f_number.value},
                   {"focal_length_mm", lens.state.focal_length_mm.value}};

  state["counts"] = {
      {"frames_in", c.frames_in.load()},     {"frames_out", c.frames_out.load()},
      {"composites", history_.composites()}, {"render_busy", c.render_busy.load()},
      {"output_busy", c.output_busy.load()}, {"render_failed", c.render_failed.load()},
      {"camera_dropped", camera.dropped},    {"placeholders", c.placeholders.load()},
      {"repeats", c.repeats.load()},         {"sink_errors", c.sink_errors.load()},
      {"lens_late", c.lens_late.load()},     {"page_records_dropped", feed_.entries_dropped()}};
  state["rpp"] = c.rpp.load();
  state["traced"] = c.traced_permille.load() / 1000.0;
  state["renderer_lost"] = c.renderer_lost.load();

  // Camera frames in per second, from the page's own samples of the count.
  state["in_fps"] = in_samples_.size() > 1 && in_samples_.back().first > in_samples_.front().first
                        ? double(in_samples_.back().second - in_samples_.front().second) /
                              (double(in_samples_.back().first - in_samples_.front().first) * 1e-9)
                        : 0.0;
  // Frames out per second (composites and fillers: what the outputs got)
  // over the last ten seconds of the history.
  const auto &minute = history_.minute();
  double out_fps = 0.0;
  if (minute.size() > 1) {
    const std::int64_t since = minute.back().output_ns - 10'000'000'000;
    std::size_t n = 0;
    std::int64_t first = minute.back().output_ns;
    for (auto it = minute.rbegin(); it != minute.rend() && it->output_ns >= since; ++it, ++n)
      first = it->output_ns;
    if (n > 1 && minute.back().output_ns > first)
      out_fps = double(n - 1) / (double(minute.back().output_ns - first) * 1e-9);
  }
  state["out_fps"] = out_fps;

  json latency = json::object();
  const auto stages = history_.latency();
  for (int s = 0; s < kStages; ++s)
    latency[std::string(stage_name(Stage(s)))] = {
        {"median_ms", stages[std::size_t(s)].median_s * 1e3},
        {"p99_ms", stages[std::size_t(s)].p99_s * 1e3}};
  state["latency"] = latency;

  // The newest composite as the record says it (frame_record.h).
  if (const auto &last = history_.last_composite()) {
    const FrameRecord &r = last->record;
    state["frame"] = {{"frame", last->output_frame},
                      {"sequence", r.sequence},
                      {"setup", r.setup},
                      {"focus_m", r.focus_m},
                      {"f_number", r.f_number},
                      {"focal_length_mm", r.focal_length_mm},
                      {"lens_fresh", r.lens_fresh},
                      {"rpp", r.rpp},
                      {"traced", r.traced},
                      {"history_samples", r.history_samples}};
    state["pose"] = {{"source", run_.pose_source},
                     {"known", r.pose_known},
                     {"fresh", r.pose_fresh},
                     {"position", vec(r.position)},
                     {"forward", vec(r.forward)},
                     {"up", vec(r.up)},
                     {"markers_seen", r.markers_seen},
                     {"found_by", r.pose_found_by ? json(r.pose_found_by) : json(nullptr)},
                     {"reprojection_px", number(r.reprojection_px)}};
  } else {
    state["frame"] = nullptr;
    state["pose"] = {{"source", run_.pose_source}};
  }
  state["http"] = {{"requests", http.requests},
                   {"refused_credentials", http.refused_credentials},
                   {"missing_credentials", http.missing_credentials},
                   {"refused_requests", http.refused_requests},
                   {"stream_clients", http.stream_clients},
                   {"preview_frames", http.preview_frames}};
  return state.dump();
}

std::string OperatorPage::history_json() {
  drain();
  json t = json::array(), focus = json::array(), iris = json::array(), zoom = json::array(),
       latency = json::array(), render = json::array();
  const auto &minute = history_.minute();
  const std::int64_t newest = minute.empty() ? 0 : minute.back().output_ns;
  for (const FeedEntry &entry : minute) {
    if (entry.kind != FeedEntry::Kind::composite)
      continue;
    t.push_back(double(entry.output_ns - newest) * 1e-9);
    focus.push_back(entry.record.focus_m);
    iris.push_back(entry.record.f_number);
    zoom.push_back(entry.record.focal_length_mm);
    latency.push_back(stage_seconds(Stage::capture_to_output, entry) * 1e3);
    render.push_back(stage_seconds(Stage::render, entry) * 1e3);
  }
  return json{{"t_s", t},
              {"focus_m", focus},
              {"f_number", iris},
              {"focal_length_mm", zoom},
              {"latency_ms", latency},
              {"render_ms", render}}
      .dump();
}

std::string OperatorPage::metrics(const web_module::HttpStats &http) {
  drain();
  const RunCounters &c = run_.counters;
  const hal::camera::CameraStatus camera = run_.camera.status();
  Metrics m;
  m.family("camhead_info", "gauge", "What runs: version, board and executor.");
  m.sample("camhead_info{version=\"" + label(CAMHEAD_VERSION) + "\",board=\"" +
               label(run_.board_name) + "\",executor=\"" + label(run_.executor) + "\"}",
           1);
  m.one("camhead_uptime_seconds", "gauge", "Seconds since the run started.",
        double(base::monotonic_ns() - start_ns_) * 1e-9);
  m.one("camhead_frames_in_total", "counter", "Camera frames captured.", double(c.frames_in));
  m.one("camhead_frames_out_total", "counter", "Composites sent to the outputs.",
        double(c.frames_out));
  m.family("camhead_fillers_total", "counter",
           "Frames sent without a new composite: the last one again, or the placeholder.");
  m.sample("camhead_fillers_total{kind=\"repeat\"}", double(c.repeats));
  m.sample("camhead_fillers_total{kind=\"placeholder\"}", double(c.placeholders));
  m.family("camhead_drops_total", "counter", "Camera frames that never reached the outputs.");
  m.sample("camhead_drops_total{cause=\"camera\"}", double(camera.dropped));
  m.sample("camhead_drops_total{cause=\"render_busy\"}", double(c.render_busy));
  m.sample("camhead_drops_total{cause=\"output_busy\"}", double(c.output_busy));
  m.sample("camhead_drops_total{cause=\"render_failed\"}", double(c.render_failed));
  m.one("camhead_lens_late_total", "counter",
        "Composites whose lens state did not cover their mid-exposure.", double(c.lens_late));
  m.one("camhead_camera_connected", "gauge", "1 while the camera delivers.",
        camera.connected && !c.camera_lost ? 1 : 0);
  m.family("camhead_output_frames_total", "counter", "Frames each output took.");
  for (const auto &sink : run_.sinks)
    m.sample("camhead_output_frames_total{output=\"" + label(sink->name()) + "\"}",
             double(sink->status().frames));
  m.family("camhead_output_errors_total", "counter", "Frames each output did not take.");
  for (const auto &sink : run_.sinks)
    m.sample("camhead_output_errors_total{output=\"" + label(sink->name()) + "\"}",
             double(sink->status().errors));
  m.one("camhead_rays_per_pixel", "gauge", "Rays per pixel of the last composite.", double(c.rpp));
  m.one("camhead_traced_ratio", "gauge", "The fraction of the last composite's pixels traced.",
        c.traced_permille / 1000.0);
  if (const auto &last = history_.last_composite()) {
    m.one("camhead_lens_focus_distance_metres", "gauge", "Focus distance of the last composite.",
          last->record.focus_m);
    m.one("camhead_lens_f_number", "gauge", "f-number of the last composite.",
          last->record.f_number);
    m.one("camhead_lens_focal_length_metres", "gauge", "Focal length of the last composite.",
          last->record.focal_length_mm * 1e-3);
    m.one("camhead_lens_fresh", "gauge", "1 when the last composite's lens state was current.",
          last->record.lens_fresh ? 1 : 0);
    m.one("camhead_pose_fresh", "gauge", "1 when the last composite's pose was current.",
          last->record.pose_fresh ? 1 : 0);
    m.one("camhead_pose_known", "gauge",
          "0 before the pose source's first pose: the composite is the camera image alone.",
          last->record.pose_known ? 1 : 0);
  }
  m.family("camhead_stage_latency_seconds", "summary",
           "Each stage of a composite's way, over the last ten seconds.");
  const auto stages = history_.latency();
  for (int s = 0; s < kStages; ++s) {
    const std::string stage = "stage=\"" + std::string(stage_name(Stage(s))) + "\"";
    const StageLatency &l = stages[std::size_t(s)];
    m.sample("camhead_stage_latency_seconds{" + stage + ",quantile=\"0.5\"}", l.median_s);
    m.sample("camhead_stage_latency_seconds{" + stage + ",quantile=\"0.99\"}", l.p99_s);
    m.sample("camhead_stage_latency_seconds_count{" + stage + "}", double(l.frames));
  }
  m.one("camhead_http_requests_total", "counter", "Requests the operator page answered.",
        double(http.requests));
  m.family("camhead_http_refused_total", "counter", "Requests the operator page refused.");
  m.sample("camhead_http_refused_total{reason=\"wrong_credentials\"}",
           double(http.refused_credentials));
  m.sample("camhead_http_refused_total{reason=\"no_credentials\"}",
           double(http.missing_credentials));
  m.sample("camhead_http_refused_total{reason=\"bad_request\"}", double(http.refused_requests));
  m.one("camhead_http_stream_clients", "gauge", "Preview and event streams open.",
        http.stream_clients);
  m.one("camhead_preview_frames_total", "counter", "Preview frames sent to clients.",
        double(http.preview_frames));
  m.family("camhead_preview_jpeg_seconds", "summary", "JPEG encoding of preview frames.");
  m.sample("camhead_preview_jpeg_seconds_sum", http.jpeg_seconds);
  m.sample("camhead_preview_jpeg_seconds_count", double(http.jpeg_frames));
  return m.take();
}

web_module::Reply OperatorPage::action(std::string_view name, std::string_view body) {
  const json request = json::parse(body.empty() ? std::string_view("{}") : body, nullptr, false);
  if (request.is_discarded() || !request.is_object())
    return {400, json{{"error", "the body is not a JSON object"}}.dump()};
  if (name == "freeze") {
    const auto frozen = request.find("frozen");
    if (frozen == request.end() || !frozen->is_boolean())
      return {400, json{{"error", "freeze: \"frozen\" must be true or false"}}.dump()};
    frozen_ = frozen->get<bool>();
    return {200, json{{"frozen", frozen_}}.dump()};
  }
  if (name == "record") {
    const auto recording = request.find("recording");
    if (recording == request.end() || !recording->is_boolean())
      return {400, json{{"error", "record: \"recording\" must be true or false"}}.dump()};
    if (recording->get<bool>()) {
      const PageRecorder::Started started = recorder_.start();
      if (!started.error.empty())
        return {409, json{{"error", "record: " + started.error}}.dump()};
      return {200, json{{"recording", true}, {"file", started.file.string()}}.dump()};
    }
    const PageRecorder::Stopped stopped = recorder_.stop();
    if (stopped.file.empty())
      return {409, json{{"error", "record: " + stopped.error}}.dump()};
    json reply{{"recording", false}, {"file", stopped.file.string()}, {"frames", stopped.frames}};
    if (!stopped.error.empty())
      reply["error"] = stopped.error;
    return {stopped.error.empty() ? 200 : 500, reply.dump()};
  }
  if (name == "mark") {
    const auto axis_field = request.find("axis");
    const auto value_field = request.find("value");
    const std::optional<MarkAxis> axis = axis_field != request.end() && axis_field->is_string()
                                             ? parse_mark_axis(axis_field->get<std::string>())
                                             : std::nullopt;
    if (!axis)
      return {400,
              json{{"error", "mark: \"axis\" must be \"focus\", \"iris\" or \"zoom\""}}.dump()};
    if (value_field == request.end() || !value_field->is_number() ||
        !std::isfinite(value_field->get<double>()) || value_field->get<double>() <= 0.0 ||
        value_field->get<double>() > 1e6)
      return {400, json{{"error", "mark: \"value\" must be the measured distance (m), "
                                  "f-number or focal length (mm), above 0"}}
                       .dump()};
    const std::optional<hal::lens::EncoderReading> reading = run_.lens.last_reading();
    const std::optional<std::int32_t> counts = !reading                   ? std::nullopt
                                               : *axis == MarkAxis::focus ? reading->focus
                                               : *axis == MarkAxis::iris  ? reading->iris
                                                                          : reading->zoom;
    if (!counts || !run_.lens.state_at(base::monotonic_ns()).connected)
      return {409,
              json{{"error", "mark: the lens source gives no " + axis_field->get<std::string>() +
                                 " counts now (not connected, or it sends calibrated "
                                 "values, which need no calibration)"}}
                  .dump()};
    const std::filesystem::path file = std::filesystem::absolute(marks_file_);
    const std::string error =
        append_mark(file, run_.board_name, *axis, *counts, value_field->get<double>());
    if (!error.empty())
      return {500, json{{"error", "mark: " + error}}.dump()};
    return {200, json{{"file", file.string()},
                      {"axis", axis_field->get<std::string>()},
                      {"counts", *counts},
                      {"value", value_field->get<double>()}}
                     .dump()};
  }
  if (name == "view")
    return capture_view();
  if (name == "reload") {
    if (run_.reloader == nullptr)
      return {409, json{{"error", "this run cannot reload its board"}}.dump()};
    run_.reloader->request();
    return {202, json{{"reload", "requested: the board is read again between two frames; the "
                                 "state's \"reload\" gives the outcome"}}
                     .dump()};
  }
  return {404, json{{"error",
                     "no action '" + std::string(name) + "' (freeze, record, mark, view, reload)"}}
                   .dump()};
}

web_module::Reply OperatorPage::capture_view() {
  // The next camera frame, whole: the frame loop copies camera frames while
  // someone watches them (as each is rendered), so the page watches until
  // one comes, a second or four frame intervals at most (its event loop
  // waits that long, once per press). A frame copied before the press is
  // not the view asked for.
  feed_.watch(View::camera, +1);
  (void)feed_.take_frame(View::camera);
  const std::int64_t wait_ns = std::max<std::int64_t>(1'000'000'000, std::llround(4e9 / run_.fps));
  const std::int64_t deadline = base::monotonic_ns() + wait_ns;
  bool fresh = false;
  while (!(fresh = feed_.take_frame(View::camera)) && base::monotonic_ns() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  feed_.watch(View::camera, -1);
  if (!fresh)
    return {503,
            json{{"error", "view: no camera frame came in " + std::to_string(wait_ns / 1'000'000) +
                               " ms (is the camera connected?)"}}
                .dump()};
  const FrameCopy &frame = feed_.frame(View::camera);
  const int w = frame.format.width, h = frame.format.height;
  std::vector<std::uint8_t> luma(std::size_t(w) * std::size_t(h));
  copy_luma(frame.format, frame.bytes, luma);
  // The PNG, and `calibrate camera` reading it, take the full range.
  if (luma_limited_range(frame.format))
    luma_to_full_range(luma);
  const LumaImage image{luma.data(), w, h, w};

  // The zoom counts only for a zoom lens: `calibrate camera --at` refuses
  // them for a prime, whose source may still send a zoom axis.
  const ProfileFacts profile = profile_facts();
  LensPlace place;
  if (const auto reading = run_.lens.last_reading();
      reading && run_.lens.state_at(base::monotonic_ns()).connected) {
    place.focus = reading->focus;
    if (profile.zooms)
      place.zoom = reading->zoom;
  }
  SavedView saved;
  if (const std::string error = save_camera_view(recordings_, image, place, saved); !error.empty())
    return {409, json{{"error", "view: " + error}}.dump()};

  json reply{{"file", saved.file.string()}, {"views", saved.views}, {"at", saved.at}};
  // How much of the board the view shows: a view the fit cannot use (the
  // board blurred, cut off or too small) is better taken again now.
  if (!run_.marker_board.empty() && !view_tracker_ && view_tracker_problem_.empty()) {
    try {
      const MarkerBoard board = load_marker_board(run_.marker_board);
      if (board.type != MarkerBoardType::charuco)
        throw MarkerModuleError(run_.marker_board.string() +
                                ": a marker field, not a ChArUco board: views are not checked");
      view_tracker_ = open_marker_tracker(board);
      board_markers_ = board.squares_x * board.squares_y / 2;
    } catch (const std::exception &e) {
      view_tracker_problem_ = e.what();
    }
  }
  if (view_tracker_) {
    // Detection does not need the lens; a nominal camera serves the call.
    const CameraModel nominal{double(w), double(w), 0.5 * w, 0.5 * h, {}};
    reply["markers_seen"] = view_tracker_->track(image, nominal, nullptr).markers_seen;
    reply["markers"] = board_markers_;
  } else {
    reply["unchecked"] = view_tracker_problem_.empty()
                             ? "the board's pose has no marker board to look for"
                             : view_tracker_problem_;
  }
  const std::string folder = saved.file.parent_path().string();
  reply["command"] =
      "camhead calibrate camera " + folder + "/*.png --board " +
      (run_.marker_board.empty() ? std::string("BOARD.json") : run_.marker_board.string()) +
      " --profile " +
      (run_.lens_profile.empty() ? std::string("PROFILE.json") : run_.lens_profile.string()) +
      " --at " + saved.at;
  // A profile's first camera model needs the sensor the pixels span.
  if (!profile.camera_model && run_.sensor_width_mm > 0.0) {
    char width[32];
    std::snprintf(width, sizeof width, "%g", run_.sensor_width_mm);
    reply["command"] = reply["command"].get<std::string>() + " --sensor-width-mm " + width;
  }
  return {200, reply.dump()};
}

OperatorPage::ProfileFacts OperatorPage::profile_facts() const {
  if (run_.lens_profile.empty())
    return {};
  try {
    const lens_control::LensProfile profile = lens_control::LensProfile::load(run_.lens_profile);
    return {profile.is_zoom(), profile.has_camera_model()};
  } catch (const lens_control::ProfileError &) {
    return {};
  }
}

} // namespace camhead::pipeline::web
