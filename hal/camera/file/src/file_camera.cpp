// The file camera: picks the reader for a path, then paces, stamps and
// buffers its frames as file_camera.h describes.
#include "camhead/hal/camera/file/file_camera.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <mutex>
#include <new>
#include <optional>
#include <string_view>
#include <system_error>

#include "buffer_ring.h"
#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/video_file/frame_pattern.h"
#include "frame_reader.h"

namespace camhead::hal::camera {
namespace {

constexpr std::int64_t kSequenceIntervalNs = 40'000'000; // 25 fps

void sleep_until(std::int64_t t_ns) {
  const timespec until{static_cast<time_t>(t_ns / 1'000'000'000),
                       static_cast<long>(t_ns % 1'000'000'000)};
  // Absolute, so that a signal does not stretch the sleep when it resumes.
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR) {
  }
}

class FileCamera final : public CameraSource {
public:
  FileCamera(std::string source, std::unique_ptr<FrameReader> reader,
             const FileCameraOptions &options, std::int64_t interval_ns)
      : source_(std::move(source)), reader_(std::move(reader)), format_(reader_->format()),
        loop_(options.loop), realtime_(options.realtime), interval_ns_(interval_ns),
        ring_(kFileCameraBuffers, base::frame_bytes(format_)) {
    status_.connected = true;
    status_.detail = name() + ": ready, " + base::describe(format_);
  }

  std::string name() const override { return "file " + source_; }
  base::VideoFormat format() const override { return format_; }
  std::int64_t frame_interval_ns() const override { return interval_ns_; }

  CaptureResult wait_frame(std::chrono::milliseconds timeout, CapturedFrame &out) override {
    try {
      return next_frame(timeout, out);
    } catch (const std::exception &e) { // std::bad_alloc from a message, at worst
      return broke(name() + ": " + e.what());
    } catch (...) {
      return broke(name() + ": unknown error");
    }
  }

  void release(const CapturedFrame &frame) override { ring_.release(frame.buffer, frame.sequence); }

  CameraStatus status() const override {
    const std::lock_guard lock(status_mutex_);
    return status_;
  }

private:
  CaptureResult next_frame(std::chrono::milliseconds timeout, CapturedFrame &out);
  FrameReader::Read read_looping(std::span<std::uint8_t> frame, std::string &error);
  // A frame that cannot be read: `failed` for a file played once, else
  // `disconnected` until the retry (file_camera.h).
  CaptureResult broke(const std::string &error);
  // A broken looping file: waits until the retry is due (or `deadline`),
  // then goes back to the first frame; true once it plays again.
  bool retry(std::int64_t deadline);
  void set_detail(std::string detail);

  const std::string source_;
  const std::unique_ptr<FrameReader> reader_;
  const base::VideoFormat format_;
  const bool loop_;
  const bool realtime_;
  const std::int64_t interval_ns_;
  BufferRing ring_;

  // The capture thread's own.
  bool ended_ = false;  // no frame follows: played once to its end, or failed
  bool failed_ = false; // ended by an error
  std::optional<std::int64_t> retry_at_ns_;
  bool started_ = false;         // a frame was delivered
  bool scheduled_ = false;       // realtime: next_due_ns_ is set
  std::int64_t first_ns_ = 0;    // offline: the first frame's stamp
  std::int64_t next_due_ns_ = 0; // realtime: when the next frame goes out
  std::uint64_t sequence_ = 0;
  std::uint64_t frames_in_pass_ = 0;
  std::uint64_t loops_ = 0;

  mutable std::mutex status_mutex_;
  CameraStatus status_;
};

CaptureResult FileCamera::next_frame(std::chrono::milliseconds timeout, CapturedFrame &out) {
  const std::int64_t deadline =
      base::monotonic_ns() +
      std::chrono::nanoseconds(std::max(timeout, std::chrono::milliseconds::zero())).count();
  if (ended_)
    return failed_ ? CaptureResult::failed : CaptureResult::ended;
  if (retry_at_ns_ && !retry(deadline))
    return CaptureResult::disconnected;
  const int index = ring_.wait_free(deadline);
  if (index < 0)
    return CaptureResult::timeout;
  if (realtime_) {
    const std::int64_t now = base::monotonic_ns();
    // The first frame (and the first after a retry) once its exposure is
    // over, as a camera's; over a frame behind, the schedule restarts
    // instead of bursting to catch up.
    if (!scheduled_)
      next_due_ns_ = now + interval_ns_;
    else if (next_due_ns_ + interval_ns_ < now)
      next_due_ns_ = now;
    scheduled_ = true;
    if (next_due_ns_ > deadline) {
      sleep_until(deadline);
      return CaptureResult::timeout;
    }
  }

  std::string error;
  switch (read_looping(ring_.bytes(index), error)) {
  case FrameReader::Read::frame:
    break;
  case FrameReader::Read::end: {
    ended_ = true;
    const std::lock_guard lock(status_mutex_);
    status_.connected = false;
    status_.detail = name() + ": ended after " + std::to_string(sequence_) + " frames";
    return CaptureResult::ended;
  }
  case FrameReader::Read::error:
    return broke(error);
  }
  // Read first, then wait: the frame leaves when it is due, not a decode later.
  if (realtime_)
    sleep_until(next_due_ns_);
  if (!started_) {
    started_ = true;
    first_ns_ = base::monotonic_ns();
  }
  out.format = format_;
  out.bytes = ring_.bytes(index);
  out.sequence = sequence_;
  // In real time a frame is delivered as its exposure ends, as a camera's,
  // stamped when that was due (a late wake-up is delivery latency, not a
  // later exposure); offline, on an exact clock from the first.
  out.timestamp_ns =
      realtime_ ? next_due_ns_ : first_ns_ + static_cast<std::int64_t>(sequence_) * interval_ns_;
  out.mark = realtime_ ? TimestampMark::end_of_frame : TimestampMark::start_of_exposure;
  out.exposure_ns = interval_ns_;
  out.buffer = index;
  ring_.hold(index, sequence_);
  ++sequence_;
  next_due_ns_ += interval_ns_;

  const std::lock_guard lock(status_mutex_);
  status_.frames = sequence_;
  if (sequence_ == 1)
    status_.detail = name() + ": playing";
  return CaptureResult::frame;
}

FrameReader::Read FileCamera::read_looping(std::span<std::uint8_t> frame, std::string &error) {
  FrameReader::Read read = reader_->read(frame, error);
  if (read == FrameReader::Read::frame)
    ++frames_in_pass_;
  if (read != FrameReader::Read::end || !loop_)
    return read;
  // A file emptied while playing must not make us spin on rewinds.
  if (frames_in_pass_ == 0) {
    error = source_ + ": loop: no frames to loop over";
    return FrameReader::Read::error;
  }
  if (!reader_->rewind(error))
    return FrameReader::Read::error;
  frames_in_pass_ = 0;
  ++loops_;
  set_detail(name() + ": playing, loop " + std::to_string(loops_ + 1));
  read = reader_->read(frame, error);
  if (read == FrameReader::Read::frame)
    ++frames_in_pass_;
  if (read == FrameReader::Read::end) {
    error = source_ + ": loop: no frames after going back to the first";
    read = FrameReader::Read::error;
  }
  return read;
}

CaptureResult FileCamera::broke(const std::string &error) {
  {
    const std::lock_guard lock(status_mutex_);
    status_.connected = false;
    ++status_.errors;
    status_.detail = error;
    if (loop_)
      status_.detail += "; playing again from the first frame in " +
                        std::to_string(kFileCameraRetryAfter.count()) + " ms";
  }
  if (!loop_) {
    ended_ = failed_ = true;
    return CaptureResult::failed;
  }
  retry_at_ns_ = base::monotonic_ns() + std::chrono::nanoseconds(kFileCameraRetryAfter).count();
  return CaptureResult::disconnected;
}

bool FileCamera::retry(std::int64_t deadline) {
  if (base::monotonic_ns() < *retry_at_ns_) {
    sleep_until(std::min(deadline, *retry_at_ns_));
    if (base::monotonic_ns() < *retry_at_ns_)
      return false;
  }
  std::string error;
  if (!reader_->rewind(error)) {
    (void)broke(error);
    return false;
  }
  retry_at_ns_.reset();
  frames_in_pass_ = 0;
  scheduled_ = false;
  const std::lock_guard lock(status_mutex_);
  status_.connected = true;
  ++status_.reconnects;
  // The error stays said until the next one (the status line reports it).
  const std::size_t cut = status_.detail.rfind("; playing again");
  status_.detail =
      name() + ": playing again from the first frame after " + status_.detail.substr(0, cut);
  return true;
}

void FileCamera::set_detail(std::string detail) {
  const std::lock_guard lock(status_mutex_);
  status_.detail = std::move(detail);
}

std::unique_ptr<FrameReader> open_reader(const FileCameraOptions &options) {
  const std::filesystem::path &path = options.path;
  const WantedSize wanted{options.width, options.height};
  std::error_code ec;
  if (video_file::FramePattern::is_pattern(path.string()) ||
      std::filesystem::is_directory(path, ec))
    return open_png_sequence_reader(path, wanted);
  // By content, not by name: a take renamed .yuv still plays.
  char magic[9] = {};
  {
    std::FILE *file = std::fopen(path.c_str(), "rbe");
    if (file == nullptr)
      throw FileCameraError(path.string() + ": open: " + std::strerror(errno));
    const std::size_t got = std::fread(magic, 1, sizeof magic, file);
    std::fclose(file);
    const std::string_view head(magic, got);
    if (head == "YUV4MPEG2")
      return open_y4m_reader(path, options.fps > 0, wanted);
    if (head.starts_with("\x89PNG\r\n\x1a\n"))
      return open_png_sequence_reader(path, wanted);
  }
  throw FileCameraError(path.string() + ": format: neither Y4M (YUV4MPEG2) nor PNG");
}

} // namespace

std::unique_ptr<CameraSource> open_file_camera(const FileCameraOptions &options) {
  const std::string source = options.path.string();
  const double fps = options.fps;
  if (!std::isfinite(fps) || fps < 0 || (fps > 0 && (fps < 0.01 || fps > 1000)))
    throw FileCameraError(source + ": fps: " + std::to_string(fps) +
                          " is not 0 (the file's rate) or 0.01 to 1000");
  std::unique_ptr<FrameReader> reader = open_reader(options);
  std::int64_t interval = fps > 0 ? std::llround(1e9 / fps) : reader->native_interval_ns();
  if (interval == 0)
    interval = kSequenceIntervalNs;
  const std::size_t bytes = base::frame_bytes(reader->format());
  try {
    return std::make_unique<FileCamera>(source, std::move(reader), options, interval);
  } catch (const std::bad_alloc &) {
    throw FileCameraError(source + ": memory: cannot allocate " +
                          std::to_string(kFileCameraBuffers) + " buffers of " +
                          std::to_string(bytes) + " bytes");
  }
}

} // namespace camhead::hal::camera
