// The libcamera camera source: CameraSession's completed Requests as frames,
// and losing and finding the camera again, as libcamera_camera.h describes.
//
// Threads: libcamera emits requestCompleted, disconnected and cameraRemoved
// on its own thread; those slots only queue the Request or note the loss,
// under mutex_, and wake wait_frame(). wait_frame() (the capture thread)
// alone creates, starts, stops and retires sessions; it never holds mutex_
// across Camera::start() or stop(), which wait for libcamera's thread, whose
// slots take mutex_. release() (any thread) queues a Request again under
// mutex_ (Camera::queueRequest only posts to libcamera's thread).
#include "libcamera_source.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <ctime>
#include <deque>
#include <mutex>
#include <utility>

#include <libcamera/camera.h>
#include <libcamera/camera_manager.h>
#include <libcamera/control_ids.h>
#include <libcamera/property_ids.h>

#include "camera_session.h"
#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/camera/frame_sequence.h"
#include "shared_manager.h"
#include "stream_settings.h"

namespace camhead::hal::camera {
namespace {

namespace settings = libcamera_settings;

// A frame's handle and a Request's cookie: the session's generation above
// the buffer index, so that a frame released after a reconnect finds its old
// session, and a Request completing for a retired session is told apart.
constexpr int kIndexBits = 5;
constexpr int kMaxBuffers = 1 << kIndexBits;
constexpr std::uint32_t kGenerations = 1u << 20;
constexpr std::uint32_t kNoGeneration = ~0u;
constexpr std::int64_t kRetryIntervalNs = 500'000'000;

void sleep_until(std::int64_t t_ns) {
  const timespec until{static_cast<time_t>(t_ns / 1'000'000'000),
                       static_cast<long>(t_ns % 1'000'000'000)};
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR) {
  }
}

std::string model_of(const libcamera::Camera &camera) {
  return camera.properties().get(libcamera::properties::Model).value_or("");
}

struct Held {
  bool held = false;
  std::uint64_t sequence = 0;
};

// A session the camera lost while the caller held some of its frames: its
// buffers stay mapped until the last is released. `stopping` while the
// capture thread still stops it; release() then only marks frames.
struct Retired {
  std::uint32_t generation = 0;
  std::unique_ptr<CameraSession> session;
  std::vector<Held> held;
  bool stopping = true;
};

bool holds_any(const std::vector<Held> &held) {
  return std::any_of(held.begin(), held.end(), [](const Held &h) { return h.held; });
}

class LibcameraSource final : public CameraSource {
public:
  LibcameraSource(std::shared_ptr<libcamera::CameraManager> manager,
                  const LibcameraCameraOptions &options, std::string label)
      : manager_(std::move(manager)), options_(options), label_(std::move(label)),
        name_("libcamera " + options.camera_id) {
    manager_->cameraRemoved.connect(this, &LibcameraSource::on_camera_removed);
  }

  ~LibcameraSource() override;

  // Takes `camera` into use (the first session); "" or why not.
  [[nodiscard]] std::string start(std::shared_ptr<libcamera::Camera> camera);

  std::string name() const override { return name_; }
  base::VideoFormat format() const override { return format_; }
  std::int64_t frame_interval_ns() const override { return interval_ns_.load(); }

  CaptureResult wait_frame(std::chrono::milliseconds timeout, CapturedFrame &out) override;
  void release(const CapturedFrame &frame) override;

  CameraStatus status() const override {
    const std::lock_guard lock(mutex_);
    return status_;
  }

private:
  // libcamera's thread.
  void on_request_completed(libcamera::Request *request);
  void on_disconnected();
  void on_camera_removed(std::shared_ptr<libcamera::Camera> camera);

  // The capture thread.
  std::string start_session(std::shared_ptr<libcamera::Camera> camera);
  void stop_session(CameraSession &session);
  bool reconnect(std::int64_t deadline);
  void lose(const std::string &reason);
  void fill(libcamera::Request &request, int index, const FrameSequence::Step &step,
            CapturedFrame &out);

  // Declared first: destroyed last, after every camera it made.
  const std::shared_ptr<libcamera::CameraManager> manager_;
  const LibcameraCameraOptions options_; // camera_id resolved
  const std::string label_;
  const std::string name_;
  base::VideoFormat format_; // the first session's, which later ones must match
  std::atomic<std::int64_t> interval_ns_{0};

  // The capture thread's own.
  FrameSequence sequence_;
  std::uint32_t last_generation_ = 0;
  std::int64_t next_try_ns_ = 0;
  bool stamp_noted_ = false;

  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  std::unique_ptr<CameraSession> session_; // null while disconnected
  std::uint32_t generation_ = kNoGeneration;
  std::deque<libcamera::Request *> completed_; // this generation's, oldest first
  std::vector<Held> held_;                     // per buffer of session_
  std::vector<Retired> retired_;
  std::string lost_; // why the camera went away, for wait_frame to act on
  CameraStatus status_;
};

LibcameraSource::~LibcameraSource() {
  manager_->cameraRemoved.disconnect(this);
  if (session_) {
    {
      const std::lock_guard lock(mutex_);
      generation_ = kNoGeneration;
    }
    stop_session(*session_);
    session_.reset();
  }
  // Frames still held past the camera's end are a caller's bug; their
  // mappings go with it.
  retired_.clear();
}

std::string LibcameraSource::start(std::shared_ptr<libcamera::Camera> camera) {
  std::string error = start_session(std::move(camera));
  if (!error.empty())
    return error;
  format_ = session_->format();
  const std::lock_guard lock(mutex_);
  status_.connected = true;
  status_.detail = "libcamera " + label_ + ": streaming " + session_->summary();
  return {};
}

void LibcameraSource::on_request_completed(libcamera::Request *request) {
  {
    const std::lock_guard lock(mutex_);
    // Requests a stop() cancels, or an old session's, are nobody's frames.
    if ((request->cookie() >> kIndexBits) != generation_)
      return;
    completed_.push_back(request);
  }
  arrived_.notify_one();
}

void LibcameraSource::on_disconnected() {
  {
    const std::lock_guard lock(mutex_);
    if (generation_ == kNoGeneration || !lost_.empty())
      return;
    lost_ = "libcamera reports it disconnected";
  }
  arrived_.notify_one();
}

void LibcameraSource::on_camera_removed(std::shared_ptr<libcamera::Camera> camera) {
  if (camera->id() != options_.camera_id)
    return;
  {
    const std::lock_guard lock(mutex_);
    if (generation_ == kNoGeneration || !lost_.empty())
      return;
    lost_ = "libcamera removed it (unplugged?)";
  }
  arrived_.notify_one();
}

std::string LibcameraSource::start_session(std::shared_ptr<libcamera::Camera> camera) {
  const std::uint32_t generation = (last_generation_ + 1) % kGenerations;
  last_generation_ = generation;
  std::string error;
  std::unique_ptr<CameraSession> session = CameraSession::create(
      camera, label_, options_, std::uint64_t{generation} << kIndexBits, error);
  if (!session)
    return error;
  if (session->buffers() > kMaxBuffers)
    return "libcamera camera " + label_ + ": the pipeline gives " +
           std::to_string(session->buffers()) + " buffers, camhead handles up to " +
           std::to_string(kMaxBuffers);
  if (format_.width != 0 && session->format() != format_)
    return "libcamera camera " + label_ + ": it is back but gives " +
           base::describe(session->format()) + ", not " + base::describe(format_);
  {
    const std::lock_guard lock(mutex_);
    generation_ = generation;
    completed_.clear();
    lost_.clear();
    held_.assign(static_cast<std::size_t>(session->buffers()), Held{});
  }
  camera->requestCompleted.connect(this, &LibcameraSource::on_request_completed);
  camera->disconnected.connect(this, &LibcameraSource::on_disconnected);
  if (error = session->start(); !error.empty()) {
    {
      const std::lock_guard lock(mutex_);
      generation_ = kNoGeneration;
    }
    stop_session(*session);
    return "libcamera camera " + label_ + ": " + error;
  }
  sequence_.restart();
  stamp_noted_ = false;
  const std::lock_guard lock(mutex_);
  session_ = std::move(session);
  return {};
}

void LibcameraSource::stop_session(CameraSession &session) {
  session.stop();
  session.camera().requestCompleted.disconnect(this);
  session.camera().disconnected.disconnect(this);
}

void LibcameraSource::lose(const std::string &reason) {
  next_try_ns_ = base::monotonic_ns() + kRetryIntervalNs;
  CameraSession *session = nullptr;
  std::uint32_t generation = 0;
  {
    const std::lock_guard lock(mutex_);
    generation = generation_;
    session = session_.get();
    retired_.push_back({generation, std::move(session_), std::move(held_), true});
    generation_ = kNoGeneration;
    completed_.clear();
    held_.clear();
    lost_.clear();
    status_.connected = false;
    status_.detail =
        "libcamera " + label_ + ": disconnected (" + reason + "); looking for it again every 0.5 s";
  }
  stop_session(*session);
  std::unique_ptr<CameraSession> done;
  {
    const std::lock_guard lock(mutex_);
    const auto it = std::find_if(retired_.begin(), retired_.end(),
                                 [&](const Retired &r) { return r.generation == generation; });
    it->stopping = false;
    if (!holds_any(it->held)) {
      done = std::move(it->session);
      retired_.erase(it);
    }
  }
  // `done` releases the camera here, outside the lock.
}

bool LibcameraSource::reconnect(std::int64_t deadline) {
  if (base::monotonic_ns() < next_try_ns_) {
    sleep_until(std::min(deadline, next_try_ns_));
    if (base::monotonic_ns() < next_try_ns_)
      return false;
  }
  next_try_ns_ = base::monotonic_ns() + kRetryIntervalNs;
  std::string error;
  if (std::shared_ptr<libcamera::Camera> camera = manager_->get(options_.camera_id); !camera)
    error = "libcamera does not list it";
  else
    error = start_session(std::move(camera));
  const std::lock_guard lock(mutex_);
  if (!error.empty()) {
    status_.detail = "libcamera " + label_ + ": disconnected, looking for it every 0.5 s; " +
                     "last try: " + error;
    return false;
  }
  ++status_.reconnects;
  status_.connected = true;
  status_.detail = "libcamera " + label_ + ": reconnected, " + session_->summary();
  return true;
}

CaptureResult LibcameraSource::wait_frame(std::chrono::milliseconds timeout, CapturedFrame &out) {
  const auto wait = std::max(timeout, std::chrono::milliseconds::zero());
  const std::int64_t deadline = base::monotonic_ns() + std::chrono::nanoseconds(wait).count();
  // steady_clock is CLOCK_MONOTONIC in libstdc++, like monotonic_ns().
  const auto until = std::chrono::steady_clock::now() + wait;
  if (!session_ && !reconnect(deadline))
    return CaptureResult::disconnected;
  const std::size_t frame_bytes = base::frame_bytes(format_);
  for (;;) {
    std::unique_lock lock(mutex_);
    arrived_.wait_until(lock, until, [&] { return !lost_.empty() || !completed_.empty(); });
    if (!lost_.empty()) {
      const std::string reason = lost_;
      lock.unlock();
      lose(reason);
      return CaptureResult::disconnected;
    }
    if (completed_.empty())
      return CaptureResult::timeout;
    libcamera::Request *request = completed_.front();
    completed_.pop_front();
    const int index = static_cast<int>(request->cookie() & (kMaxBuffers - 1));
    const libcamera::FrameBuffer *buffer = request->findBuffer(session_->stream());
    std::string fault;
    if (buffer == nullptr) {
      fault = "a Request without its buffer";
    } else if (request->status() != libcamera::Request::RequestComplete ||
               buffer->metadata().status != libcamera::FrameMetadata::FrameSuccess) {
      fault = buffer->metadata().status == libcamera::FrameMetadata::FrameCancelled ||
                      request->status() == libcamera::Request::RequestCancelled
                  ? "a cancelled buffer"
                  : "a buffer the pipeline flagged as failed";
    } else {
      std::size_t used = 0;
      for (const libcamera::FrameMetadata::Plane &plane : buffer->metadata().planes())
        used += plane.bytesused;
      if (used < frame_bytes)
        fault = "a short buffer (" + std::to_string(used) + " of " + std::to_string(frame_bytes) +
                " bytes)";
    }
    if (!fault.empty()) {
      // Never shown; the Request goes back at once.
      ++status_.errors;
      status_.detail = "libcamera " + label_ + ": dropped " + fault;
      if (std::string error = session_->queue(index); !error.empty()) {
        lock.unlock();
        lose(error);
        return CaptureResult::disconnected;
      }
      continue;
    }
    const FrameSequence::Step step = sequence_.next(buffer->metadata().sequence);
    held_[static_cast<std::size_t>(index)] = {true, step.sequence};
    status_.dropped += step.dropped;
    ++status_.frames;
    fill(*request, index, step, out);
    return CaptureResult::frame;
  }
}

// Under mutex_, for the Request at `index` that just completed.
void LibcameraSource::fill(libcamera::Request &request, int index, const FrameSequence::Step &step,
                           CapturedFrame &out) {
  const libcamera::ControlList &metadata = request.metadata();
  const libcamera::FrameBuffer &buffer = *request.findBuffer(session_->stream());
  std::int64_t stamp = 0;
  if (const std::optional<std::int64_t> sensor = metadata.get(libcamera::controls::SensorTimestamp))
    stamp = *sensor;
  else
    stamp = static_cast<std::int64_t>(buffer.metadata().timestamp);
  if (!stamp_noted_) {
    stamp_noted_ = true;
    if (!metadata.get(libcamera::controls::SensorTimestamp))
      status_.detail += "; no SensorTimestamp: the buffers' own timestamps are used";
  }
  if (const std::optional<std::int64_t> duration = metadata.get(libcamera::controls::FrameDuration))
    interval_ns_.store(*duration * 1000);
  const std::optional<std::int32_t> exposure_us = metadata.get(libcamera::controls::ExposureTime);
  out = CapturedFrame{
      .format = format_,
      .bytes = session_->bytes(index),
      .sequence = step.sequence,
      .timestamp_ns = stamp,
      .mark = TimestampMark::start_of_exposure,
      .exposure_ns = exposure_us ? std::int64_t{*exposure_us} * 1000 : 0,
      .buffer = static_cast<int>((generation_ << kIndexBits) | static_cast<std::uint32_t>(index)),
  };
}

void LibcameraSource::release(const CapturedFrame &frame) {
  if (frame.buffer < 0)
    return;
  const auto generation = static_cast<std::uint32_t>(frame.buffer) >> kIndexBits;
  const auto index = static_cast<std::size_t>(frame.buffer & (kMaxBuffers - 1));
  std::unique_ptr<CameraSession> done;
  {
    const std::lock_guard lock(mutex_);
    if (session_ && generation == generation_) {
      // A second or stale release is a caller bug with nothing to recover:
      // ignored, as the V4L2 and file cameras do.
      if (index >= held_.size() || !held_[index].held || held_[index].sequence != frame.sequence)
        return;
      held_[index].held = false;
      if (std::string error = session_->queue(static_cast<int>(index));
          !error.empty() && lost_.empty()) {
        lost_ = error;
        arrived_.notify_one();
      }
      return;
    }
    for (auto it = retired_.begin(); it != retired_.end(); ++it) {
      if (it->generation != generation || index >= it->held.size() || !it->held[index].held ||
          it->held[index].sequence != frame.sequence)
        continue;
      it->held[index].held = false;
      if (!it->stopping && !holds_any(it->held)) {
        done = std::move(it->session);
        retired_.erase(it);
      }
      break;
    }
  }
  // `done` releases its camera here, outside the lock.
}

} // namespace

std::unique_ptr<CameraSource> open_libcamera_source(const LibcameraCameraOptions &options,
                                                    std::string &error) {
  const std::string what = options.camera_id.empty() ? "libcamera" : options.camera_id;
  if (const std::string reason = settings::check_options(options); !reason.empty()) {
    error = "libcamera camera " + what + ": " + reason;
    return nullptr;
  }
  std::shared_ptr<libcamera::CameraManager> manager = shared_camera_manager(error);
  if (!manager)
    return nullptr;
  std::shared_ptr<libcamera::Camera> camera;
  if (options.camera_id.empty()) {
    const std::vector<std::shared_ptr<libcamera::Camera>> cameras = manager->cameras();
    if (cameras.empty()) {
      error = "libcamera: no camera found (no driver for one loaded, or, without udevd, no "
              "/run/udev/data entries for its nodes)";
      return nullptr;
    }
    camera = cameras.front();
  } else if (camera = manager->get(options.camera_id); !camera) {
    std::string known;
    for (const std::shared_ptr<libcamera::Camera> &other : manager->cameras())
      known += (known.empty() ? "" : ", ") + settings::camera_label(other->id(), model_of(*other));
    error = "libcamera: no camera " + options.camera_id + "; it lists " +
            (known.empty() ? std::string("none") : known);
    return nullptr;
  }
  LibcameraCameraOptions resolved = options;
  resolved.camera_id = camera->id();
  auto source = std::make_unique<LibcameraSource>(
      manager, resolved, settings::camera_label(camera->id(), model_of(*camera)));
  if (error = source->start(std::move(camera)); !error.empty())
    return nullptr;
  return source;
}

std::vector<std::string> list_cameras(std::string &error) {
  std::shared_ptr<libcamera::CameraManager> manager = shared_camera_manager(error);
  std::vector<std::string> lines;
  if (!manager)
    return lines;
  for (const std::shared_ptr<libcamera::Camera> &camera : manager->cameras())
    lines.push_back(settings::camera_label(camera->id(), model_of(*camera)));
  return lines;
}

} // namespace camhead::hal::camera
