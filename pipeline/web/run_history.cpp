#include "run_history.h"

#include <algorithm>
#include <cmath>

namespace camhead::pipeline::web {
namespace {

constexpr std::int64_t kMinuteNs = 60'000'000'000;

double between(std::int64_t from_ns, std::int64_t to_ns) {
  return from_ns > 0 && to_ns >= from_ns ? double(to_ns - from_ns) * 1e-9 : 0.0;
}

// The value below which a `q` fraction of `sorted` lies (nearest rank).
double quantile(const std::vector<double> &sorted, double q) {
  const std::size_t rank = std::size_t(std::ceil(q * double(sorted.size())));
  return sorted[std::min(sorted.size() - 1, rank > 0 ? rank - 1 : 0)];
}

} // namespace

std::string_view stage_name(Stage stage) {
  switch (stage) {
  case Stage::capture_to_output:
    return "capture_to_output";
  case Stage::delivery:
    return "delivery";
  case Stage::queue:
    return "queue";
  case Stage::lens_wait:
    return "lens_wait";
  case Stage::pose_wait:
    return "pose_wait";
  case Stage::render:
    return "render";
  case Stage::trace:
    return "trace";
  case Stage::output:
    return "output";
  }
  return "?";
}

double stage_seconds(Stage stage, const FeedEntry &entry) {
  const FrameRecord &r = entry.record;
  switch (stage) {
  case Stage::capture_to_output:
    return between(r.capture_ns, entry.output_ns);
  case Stage::delivery:
    return between(r.capture_ns, r.delivered_ns);
  case Stage::queue:
    return between(r.delivered_ns, r.render_start_ns);
  case Stage::lens_wait:
    return r.lens_wait_s;
  case Stage::pose_wait:
    return r.pose_wait_s;
  case Stage::render:
    return between(r.render_start_ns, r.render_end_ns);
  case Stage::trace:
    return r.trace_s;
  case Stage::output:
    return between(r.render_end_ns, entry.output_ns);
  }
  return 0.0;
}

void RunHistory::add(const FeedEntry &entry) {
  if (entry.kind == FeedEntry::Kind::composite) {
    ++composites_;
    last_ = entry;
  } else {
    ++fillers_;
  }
  lines_.push_back(entry);
  while (!lines_.empty() && entry.output_ns - lines_.front().output_ns > kMinuteNs)
    lines_.pop_front();
}

std::array<StageLatency, kStages> RunHistory::latency(double window_s) const {
  std::array<StageLatency, kStages> out{};
  if (lines_.empty())
    return out;
  const std::int64_t since = lines_.back().output_ns - std::int64_t(window_s * 1e9);
  std::vector<double> values;
  for (int s = 0; s < kStages; ++s) {
    values.clear();
    for (const FeedEntry &entry : lines_)
      if (entry.kind == FeedEntry::Kind::composite && entry.output_ns >= since)
        values.push_back(stage_seconds(Stage(s), entry));
    if (values.empty())
      continue;
    std::sort(values.begin(), values.end());
    out[std::size_t(s)] = {quantile(values, 0.5), quantile(values, 0.99), values.size()};
  }
  return out;
}

} // namespace camhead::pipeline::web
