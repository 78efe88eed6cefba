// See run_status.h.
#include "run_status.h"

#include <cinttypes>
#include <cmath>
#include <utility>

#include <unistd.h>

namespace camhead::pipeline {

RunStatus::RunStatus(std::FILE *out, const hal::camera::CameraSource &camera, const LensHub &lens,
                     const std::vector<std::unique_ptr<hal::output::FrameSink>> &sinks,
                     const RunCounters &counters, std::string executor, std::string pose_source)
    : out_(out), tty_(isatty(fileno(out)) != 0), camera_(camera), lens_(lens), sinks_(sinks),
      counters_(counters), executor_(std::move(executor)), pose_source_(std::move(pose_source)),
      sink_errors_seen_(sinks.size(), 0) {}

void RunStatus::start() {
  std::fprintf(out_, "camhead run: %s -> %zu output%s, %s, lens %s\n", camera_.name().c_str(),
               sinks_.size(), sinks_.size() == 1 ? "" : "s", executor_.c_str(),
               lens_.source_name().c_str());
}

void RunStatus::second(std::int64_t now_ns, double dt, std::uint64_t in, std::uint64_t out) {
  report_camera();
  report_sink_errors();
  const hal::camera::CameraStatus cam = camera_.status();
  const LensSnapshot lens = lens_.state_at(now_ns);
  char focus[32];
  if (std::isinf(lens.state.focus_distance_m.value))
    std::snprintf(focus, sizeof focus, "inf");
  else
    std::snprintf(focus, sizeof focus, "%.2f m", lens.state.focus_distance_m.value);
  const char *alarm = counters_.renderer_lost ? "  GPU LOST: placeholder"
                      : counters_.camera_lost ? "  CAMERA LOST: placeholder"
                                              : "";
  char output_errors[48] = "";
  if (const std::uint64_t errors = counters_.sink_errors; errors > 0)
    std::snprintf(output_errors, sizeof output_errors, "  OUTPUT ERRORS %" PRIu64, errors);
  // A tracked pose, and whether the last frame's was current.
  char pose[128] = "";
  if (pose_source_ != "static")
    std::snprintf(pose, sizeof pose, "  pose %s%s", pose_source_.c_str(),
                  counters_.pose_unknown ? " (none yet: camera image only)"
                  : counters_.pose_stale ? " (stale)"
                                         : "");
  char lens_late[64] = "";
  if (const std::uint64_t late = counters_.lens_late; late > 0)
    std::snprintf(lens_late, sizeof lens_late, " (%" PRIu64 " frames without it)", late);
  char line[512];
  std::snprintf(line, sizeof line,
                "in %5.1f fps  out %5.1f fps  rpp %.4g  traced %.0f%%  dropped %" PRIu64
                " (camera %" PRIu64 ", render busy %" PRIu64 ", output busy %" PRIu64
                ")  focus %s f/%.1f %.0f mm%s%s%s  latency %.0f ms%s%s",
                double(in) / dt, double(out) / dt, counters_.rpp.load(),
                0.1 * counters_.traced_permille.load(),
                cam.dropped + counters_.render_busy + counters_.output_busy, cam.dropped,
                counters_.render_busy.load(), counters_.output_busy.load(), focus,
                lens.state.f_number.value, lens.state.focal_length_mm.value,
                lens.fresh ? "" : " (stale)", lens_late, pose,
                1e-6 * double(counters_.latency_ns.load()), alarm, output_errors);
  last_line_ = line;
  std::fprintf(out_, "%s%s%s", tty_ ? "\r\033[K" : "", line, tty_ ? "" : "\n");
  std::fflush(out_);
}

void RunStatus::note(const std::string &text) {
  std::fprintf(out_, "%scamhead run: %s\n", tty_ ? "\r\033[K" : "", text.c_str());
  std::fflush(out_);
}

void RunStatus::end() {
  if (tty_)
    std::fprintf(out_, "\n");
  tty_ = false;
}

// An output that failed since the last look says what failed (the device or
// file, and why) on a line of its own: a count alone tells nobody which of
// them ran out of disk.
void RunStatus::report_sink_errors() {
  for (std::size_t i = 0; i < sinks_.size(); ++i) {
    const hal::output::SinkStatus status = sinks_[i]->status();
    if (status.errors == sink_errors_seen_[i])
      continue;
    std::fprintf(out_, "%scamhead run: %s (%" PRIu64 " failed so far)\n", tty_ ? "\r\033[K" : "",
                 status.detail.c_str(), status.errors);
    sink_errors_seen_[i] = status.errors;
  }
}

// A camera that failed or went away says why: once for each new error (a
// take's frame that cannot be read; the detail keeps it after the camera is
// back), and once each time a lost camera's word changes (a device gone).
void RunStatus::report_camera() {
  const hal::camera::CameraStatus status = camera_.status();
  const bool new_error = status.errors != camera_errors_seen_;
  const bool new_loss = !status.connected && status.detail != camera_detail_seen_;
  camera_errors_seen_ = status.errors;
  if (!new_error && !new_loss)
    return;
  camera_detail_seen_ = status.detail;
  std::fprintf(out_, "%scamhead run: camera: %s\n", tty_ ? "\r\033[K" : "", status.detail.c_str());
}

} // namespace camhead::pipeline
