// The operator page of a run (`camhead run --http`): what the web module's
// server (web_server.h) serves, read from the run as it goes. The frame
// loop only feeds it (web_feed.h); everything else here runs on the
// server's thread: the history of the last minute, the state as JSON, the
// metrics for Prometheus, and the operator's actions.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "camhead/hal/camera/camera_source.h"
#include "camhead/hal/output/frame_sink.h"
#include "page_recorder.h"
#include "preview_image.h"
#include "run/lens_hub.h"
#include "run/run_counters.h"
#include "run/setup_reloader.h"
#include "run_history.h"
#include "tracking/marker_tracker.h"
#include "web_access.h"
#include "web_feed.h"
#include "web_module_abi.h"

namespace camhead::pipeline::web {

// What the page reads of the run; each must outlive the page.
struct RunView {
  std::string board_name;
  std::string board_file;
  std::string board_description;
  const hal::camera::CameraSource &camera;
  const LensHub &lens;
  const std::vector<std::unique_ptr<hal::output::FrameSink>> &sinks;
  const RunCounters &counters;
  std::string executor;
  std::string pose_source;
  double fps = 25.0;
  // Asked by the reload action, and its outcome shown; null: the run
  // cannot reload (RunOptions::reload).
  SetupReloader *reloader = nullptr;
  // The format of the output the record button writes (yuyv or nv12);
  // none: no output of the run is in one.
  std::optional<base::VideoFormat> record_format;
  // For the camera-calibration views: a marker pose's board file (the views
  // are checked for its markers; empty: none), and the lens profile the
  // fit writes into (empty: the board has none).
  std::filesystem::path marker_board;
  std::filesystem::path lens_profile;
  // The width of the sensor the camera's frames span (the board's camera).
  double sensor_width_mm = 0.0;
};

class OperatorPage final : public web_module::Host {
public:
  // Starts serving (throws WebAccessError for a password the address needs
  // and the file does not give, WebError when the server cannot start).
  OperatorPage(const WebOptions &options, RunView run, const base::VideoFormat &composite,
               const base::VideoFormat &camera);
  ~OperatorPage(); // stops serving first
  OperatorPage(const OperatorPage &) = delete;
  OperatorPage &operator=(const OperatorPage &) = delete;

  // The frame loop's side (web_feed.h, page_recorder.h).
  [[nodiscard]] WebFeed &feed() { return feed_; }
  [[nodiscard]] PageRecorder &recorder() { return recorder_; }
  // Where it is served, as bound ("http://127.0.0.1:8080/").
  [[nodiscard]] std::string url() const;

  // web_module::Host, on the server's thread.
  void watch(View view, int delta) override;
  const PreviewImage &preview(View view) override;
  std::string state_json(const web_module::HttpStats &http) override;
  std::string history_json() override;
  std::string metrics(const web_module::HttpStats &http) override;
  web_module::Reply action(std::string_view name, std::string_view body) override;

private:
  // Takes the record lines the frame loop sent since the last call.
  void drain();
  // The "view" action: the next camera frame saved for `calibrate camera`
  // (camera_views.h), checked for the marker board's markers.
  web_module::Reply capture_view();
  // What `calibrate camera` asks of the board's lens profile (read afresh:
  // a reload may have changed it): whether it is a zoom's (then the views'
  // zoom counts; assumed without a profile, or one that does not load),
  // and whether it has a camera model yet (else the sensor's width).
  struct ProfileFacts {
    bool zooms = true, camera_model = false;
  };
  [[nodiscard]] ProfileFacts profile_facts() const;

  RunView run_;
  WebFeed feed_;
  RunHistory history_;
  std::deque<std::pair<std::int64_t, std::uint64_t>> in_samples_; // (when, frames in)
  PreviewImage previews_[kViews]; // the newest frame of each view, shrunk
  PageRecorder recorder_;
  std::filesystem::path recordings_;
  std::filesystem::path marks_file_; // the calibration marks (calibration_marks.h)
  // The views' check: a tracker of the marker board, opened at the first
  // view (or why it cannot be), and how many markers the board has.
  std::unique_ptr<MarkerTracker> view_tracker_;
  std::string view_tracker_problem_;
  int board_markers_ = 0;
  std::int64_t start_ns_;
  bool frozen_ = false;                        // the preview holds its frame (the outputs go on)
  std::unique_ptr<web_module::Server> server_; // last: stopped first
};

} // namespace camhead::pipeline::web
