// The recording decorator. See trace_recorder.h for the crash-safety model.
#include "camhead/hal/lens/trace/trace_recorder.h"

#include <cstdint>
#include <span>

#include "camhead/hal/lens/trace/lens_trace.h"

namespace camhead::hal::lens {
namespace {

// Whole lines go out at least this often by size, whatever the interval, so
// the buffer stays small at high rates.
constexpr std::size_t kMaxPending = 64 * 1024;

std::optional<base::PartialFile> open_partial(const std::filesystem::path &path) {
  std::string error;
  std::optional<base::PartialFile> file = base::PartialFile::create(path, error);
  if (!file) {
    throw TraceError(path.string(), 0, "", error);
  }
  return file;
}

} // namespace

TraceRecorder::TraceRecorder(std::unique_ptr<LensEncoder> inner, std::filesystem::path path,
                             TraceRecorderOptions options)
    : inner_(std::move(inner)), path_(std::move(path)),
      flush_interval_ns_(std::chrono::nanoseconds(options.flush_interval).count()),
      file_(open_partial(path_)) {
  std::string comment = "recorded from " + inner_->name();
  if (!options.comment.empty()) {
    comment += "\n" + options.comment;
  }
  pending_ = format_trace_header(comment);
  flush();
  if (!error_.empty()) {
    throw TraceError(partial_path().string(), 0, "", error_);
  }
}

TraceRecorder::~TraceRecorder() {
  if (!closed_ && file_) {
    flush();
    if (file_)
      file_->abandon();
  }
}

std::filesystem::path TraceRecorder::partial_path() const {
  if (file_)
    return file_->partial_path();
  std::filesystem::path p = path_;
  p += ".partial";
  return p;
}

std::string TraceRecorder::name() const {
  return inner_->name();
}

void TraceRecorder::poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) {
  const std::size_t first = out.size();
  inner_->poll(timeout, out);
  if (!file_) {
    return;
  }
  for (std::size_t i = first; i < out.size(); ++i) {
    record(out[i]);
  }
  // Flush at most once per poll: on a quiet poll, when the readings have
  // moved on by the interval, or when the buffer is large.
  const bool quiet = out.size() == first;
  const bool interval_passed = last_ns_ && *last_ns_ - last_flush_ns_ >= flush_interval_ns_;
  if (!pending_.empty() && (quiet || interval_passed || pending_.size() >= kMaxPending)) {
    flush();
  }
}

void TraceRecorder::record(const EncoderReading &r) {
  if (last_ns_ && r.t_ns < *last_ns_) {
    ++skipped_;
    return;
  }
  if (!origin_ns_) {
    origin_ns_ = r.t_ns;
    last_flush_ns_ = r.t_ns;
  }
  last_ns_ = r.t_ns;
  EncoderReading row = r;
  row.t_ns -= *origin_ns_;
  pending_ += format_trace_row(row);
  pending_ += '\n';
  ++recorded_;
}

void TraceRecorder::flush() {
  if (!file_ || pending_.empty()) {
    return;
  }
  std::string error;
  const std::span bytes(reinterpret_cast<const std::uint8_t *>(pending_.data()), pending_.size());
  if (!file_->write(bytes, error)) {
    fail(error);
    return;
  }
  pending_.clear();
  if (last_ns_) {
    last_flush_ns_ = *last_ns_;
  }
}

void TraceRecorder::fail(const std::string &what) {
  if (error_.empty()) {
    error_ = what;
  }
  if (file_) {
    file_->abandon(); // what was written stays in PATH.partial
    file_.reset();
  }
  pending_.clear();
}

void TraceRecorder::close() {
  if (closed_) {
    return;
  }
  closed_ = true;
  const std::filesystem::path partial = partial_path();
  flush();
  std::string error;
  if (file_ && !file_->commit(true, error)) {
    fail(error);
  }
  file_.reset();
  if (!error_.empty()) {
    throw TraceError(partial.string(), 0, "", "recording stopped: " + error_);
  }
}

EncoderStatus TraceRecorder::status() const {
  EncoderStatus s = inner_->status();
  if (!error_.empty()) {
    s.detail += "; recording to " + partial_path().string() + " stopped: " + error_;
  }
  return s;
}

} // namespace camhead::hal::lens
