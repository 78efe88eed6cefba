// The operator page's memory of the run: the record lines of the last
// minute (web_feed.h), and what the page shows of them: the latency of
// each stage of the frame (median and 99th percentile over the last ten
// seconds) and the lens and latency over the minute for its plots.
//
// Thread safety: one thread (the page's).
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <string_view>
#include <vector>

#include "web_feed.h"

namespace camhead::pipeline::web {

// The stages of a composite's way through the pipeline, each in seconds
// from its record (frame_record.h).
enum class Stage {
  capture_to_output, // the whole: the camera's timestamp to the outputs
  delivery,          // the camera's timestamp to the frame handed over
  queue,             // handed over to the render thread starting it
  lens_wait,         // waiting for the lens readings of its mid-exposure
  pose_wait,         // waiting for the marker tracker
  render,            // the renderer's call (decode, trace, encode)
  trace,             // of it, tracing
  output,            // rendered to sent to every output
};
inline constexpr int kStages = 8;
[[nodiscard]] std::string_view stage_name(Stage stage);
[[nodiscard]] double stage_seconds(Stage stage, const FeedEntry &entry);

struct StageLatency {
  double median_s = 0.0, p99_s = 0.0;
  std::size_t frames = 0; // composites it is over
};

class RunHistory {
public:
  // Adds a record line; lines older than the minute before it go.
  void add(const FeedEntry &entry);

  // Each stage over the composites of the `window_s` seconds before the newest line.
  [[nodiscard]] std::array<StageLatency, kStages> latency(double window_s = 10.0) const;
  // The newest composite's line, if one came.
  [[nodiscard]] const std::optional<FeedEntry> &last_composite() const { return last_; }
  // Every line of the last minute, oldest first.
  [[nodiscard]] const std::deque<FeedEntry> &minute() const { return lines_; }
  // Record lines by kind since the run started.
  [[nodiscard]] std::uint64_t composites() const { return composites_; }
  [[nodiscard]] std::uint64_t fillers() const { return fillers_; }

private:
  std::deque<FeedEntry> lines_;
  std::optional<FeedEntry> last_;
  std::uint64_t composites_ = 0, fillers_ = 0;
};

} // namespace camhead::pipeline::web
