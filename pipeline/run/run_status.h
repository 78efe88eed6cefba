// The live pipeline's status line (`camhead run`): redrawn in place on a
// terminal, a line a second in logs (the journal), and a line of its own
// for each camera or output that fails, naming it and why.
//
// Thread safety: one thread (the run's status thread) calls every member.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "camhead/hal/camera/camera_source.h"
#include "camhead/hal/output/frame_sink.h"
#include "lens_hub.h"
#include "run_counters.h"

namespace camhead::pipeline {

class RunStatus {
public:
  // Writes to `out` (a terminal or not, as isatty() says); the rest is read
  // as the run goes and must outlive this.
  RunStatus(std::FILE *out, const hal::camera::CameraSource &camera, const LensHub &lens,
            const std::vector<std::unique_ptr<hal::output::FrameSink>> &sinks,
            const RunCounters &counters, std::string executor, std::string pose_source);

  // What runs: the camera, the outputs, the executor, the lens.
  void start();
  // A second's line (frames in and out since the last, over `dt` seconds),
  // after a line for each camera or output failure since the last.
  void second(std::int64_t now_ns, double dt, std::uint64_t in, std::uint64_t out);
  // The last second's line as second() wrote it, without the terminal's
  // control codes (the service's STATUS=); empty before the first.
  [[nodiscard]] const std::string &last_line() const { return last_line_; }
  // A line of its own ("camhead run: reloaded ...").
  void note(const std::string &text);
  // Ends the line being redrawn; from here every line is a line of its own.
  void end();
  // A line for each output that failed since the last look (also after end()).
  void report_sink_errors();

private:
  void report_camera();

  std::FILE *out_;
  bool tty_;
  const hal::camera::CameraSource &camera_;
  const LensHub &lens_;
  const std::vector<std::unique_ptr<hal::output::FrameSink>> &sinks_;
  const RunCounters &counters_;
  const std::string executor_;
  const std::string pose_source_;               // "static" is not shown
  std::vector<std::uint64_t> sink_errors_seen_; // reported so far
  std::string camera_detail_seen_;              // reported last
  std::uint64_t camera_errors_seen_ = 0;        // reported so far
  std::string last_line_;
};

} // namespace camhead::pipeline
