// The V4L2 camera: delivers CaptureStream's buffers as frames, and closes
// and reopens the device as v4l2_camera.h describes.
//
// Threads: wait_frame() runs on the capture thread, which alone opens,
// polls and closes streams; release() and status() come from any thread.
// mutex_ guards the current stream's buffer ioctls and bookkeeping, the
// streams retired after a loss, and the status, so that release() never
// queues a buffer on a descriptor that is being closed. poll() runs without
// it, on a descriptor only this thread can close.
#include "camhead/hal/camera/v4l2/v4l2_camera.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <mutex>
#include <utility>
#include <vector>

#include <poll.h>

#include "buffer_timestamp.h"
#include "camhead/base/monotonic_clock.h"
#include "camhead/base/realtime_stamp.h"
#include "camhead/hal/camera/frame_sequence.h"
#include "camhead/hal/v4l2/reconnect_schedule.h"
#include "capture_stream.h"

namespace camhead::hal::camera {
namespace {

using v4l2::errno_text;

// A frame's handle: the stream's generation above the buffer index, so that
// a frame released after a reopen finds its old stream, not a new buffer.
constexpr int kIndexBits = 5;
constexpr std::uint32_t kGenerations = 1u << 20;
constexpr std::int64_t kExposureReadIntervalNs = 500'000'000;

void sleep_until(std::int64_t t_ns) {
  const timespec until{static_cast<time_t>(t_ns / 1'000'000'000),
                       static_cast<long>(t_ns % 1'000'000'000)};
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR) {
  }
}

struct OwnedStream {
  std::uint32_t generation = 0;
  std::unique_ptr<CaptureStream> stream;
};

class V4l2Camera final : public CameraSource {
public:
  V4l2Camera(StreamRequest request, std::unique_ptr<CaptureStream> stream)
      : request_(std::move(request)), name_("v4l2 " + request_.device), format_(stream->format()),
        interval_ns_(stream->interval_ns()) {
    read_exposure(*stream, base::monotonic_ns());
    status_.connected = true;
    status_.detail = name_ + ": streaming, " + stream->summary();
    current_ = {0, std::move(stream)};
  }

  std::string name() const override { return name_; }
  base::VideoFormat format() const override { return format_; }
  std::int64_t frame_interval_ns() const override { return interval_ns_; }

  CaptureResult wait_frame(std::chrono::milliseconds timeout, CapturedFrame &out) override;
  void release(const CapturedFrame &frame) override;

  CameraStatus status() const override {
    const std::lock_guard lock(mutex_);
    return status_;
  }

private:
  bool reconnect(std::int64_t deadline);
  void lose(const std::string &reason);
  void read_exposure(const CaptureStream &stream, std::int64_t now);
  void note_clock(StampClock clock);

  const StreamRequest request_;
  const std::string name_;
  const base::VideoFormat format_;
  const std::int64_t interval_ns_;

  // The capture thread's own.
  FrameSequence sequence_;
  v4l2::ReconnectSchedule schedule_;
  std::uint32_t generation_ = 0;
  std::int64_t exposure_ns_ = 0;
  std::int64_t next_exposure_read_ns_ = 0;
  bool has_exposure_ = false;
  bool clock_noted_ = false;
  StampClock clock_ = StampClock::monotonic;

  mutable std::mutex mutex_;
  OwnedStream current_;              // stream null while disconnected
  std::vector<OwnedStream> retired_; // closed, with buffers the caller still holds
  std::string broken_;               // why a release could not queue its buffer
  CameraStatus status_;
};

CaptureResult V4l2Camera::wait_frame(std::chrono::milliseconds timeout, CapturedFrame &out) {
  const std::int64_t deadline =
      base::monotonic_ns() +
      std::chrono::nanoseconds(std::max(timeout, std::chrono::milliseconds::zero())).count();
  if (!current_.stream && !reconnect(deadline))
    return CaptureResult::disconnected;
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      if (!broken_.empty()) {
        const std::string reason = std::exchange(broken_, {});
        lock.unlock();
        lose(reason);
        return CaptureResult::disconnected;
      }
    }
    const std::int64_t left = deadline - base::monotonic_ns();
    pollfd p{current_.stream->fd(), POLLIN, 0};
    const int ready = ::poll(&p, 1, left > 0 ? static_cast<int>((left + 999'999) / 1'000'000) : 0);
    if (ready < 0 && errno == EINTR)
      continue;
    if (ready < 0) {
      lose("poll: " + errno_text(errno));
      return CaptureResult::disconnected;
    }
    if (ready == 0)
      return CaptureResult::timeout;
    if ((p.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
      // vb2 answers POLLERR when the queue is in error, V4L2 itself
      // POLLERR | POLLHUP once the device is unregistered (unplugged).
      lose((p.revents & POLLHUP) != 0 ? "the device hung up (unplugged?)"
                                      : "poll reports an error on the device");
      return CaptureResult::disconnected;
    }

    v4l2_buffer buffer{};
    CaptureStream &stream = *current_.stream;
    std::unique_lock lock(mutex_);
    const CaptureStream::Dequeued dequeued = stream.dequeue(buffer);
    if (dequeued == CaptureStream::Dequeued::nothing) {
      lock.unlock();
      if (base::monotonic_ns() >= deadline)
        return CaptureResult::timeout;
      continue;
    }
    if (dequeued == CaptureStream::Dequeued::failed) {
      const int err = errno;
      lock.unlock();
      lose("VIDIOC_DQBUF: " + errno_text(err));
      return CaptureResult::disconnected;
    }
    const int index = static_cast<int>(buffer.index);
    // A compressed frame's size is its own; it is checked by decoding it.
    const std::size_t frame_bytes = stream.compressed() ? 1 : base::frame_bytes(format_);
    if ((buffer.flags & V4L2_BUF_FLAG_ERROR) != 0 || buffer.bytesused < frame_bytes) {
      // Corrupt (a USB packet lost) or short: never shown, the buffer goes back.
      ++status_.errors;
      status_.detail = name_ + ": dropped a " +
                       ((buffer.flags & V4L2_BUF_FLAG_ERROR) != 0
                            ? std::string("buffer the driver flagged as corrupt")
                            : "short buffer (" + std::to_string(buffer.bytesused) + " of " +
                                  std::to_string(frame_bytes) + " bytes)");
      if (!stream.queue(index)) {
        const int err = errno;
        lock.unlock();
        lose("VIDIOC_QBUF: " + errno_text(err));
        return CaptureResult::disconnected;
      }
      continue;
    }
    // Both clocks at one instant (realtime_stamp.h): a driver's wall-clock
    // stamp is moved by their offset. Without one (a realtime step in every
    // bracket) such a stamp is judged on no clock.
    const base::ClockPair clocks = base::read_clock_pair();
    const std::int64_t now = clocks.monotonic_ns;
    const BufferStamp stamp = buffer_stamp(buffer.flags,
                                           std::int64_t{buffer.timestamp.tv_sec} * 1'000'000'000 +
                                               std::int64_t{buffer.timestamp.tv_usec} * 1'000,
                                           clocks);
    const FrameSequence::Step step = sequence_.next(buffer.sequence);
    stream.hold(index, step.sequence);
    status_.dropped += step.dropped;
    lock.unlock();

    // Decoded outside the lock (it takes milliseconds): nobody else touches
    // a buffer that has not been delivered.
    std::string undecodable;
    if (stream.compressed() && !stream.decode(index, buffer.bytesused, undecodable)) {
      lock.lock();
      ++status_.errors;
      status_.detail = name_ + ": dropped a frame: " + undecodable;
      stream.unhold(index);
      if (!stream.queue(index)) {
        const int err = errno;
        lock.unlock();
        lose("VIDIOC_QBUF: " + errno_text(err));
        return CaptureResult::disconnected;
      }
      continue;
    }
    lock.lock();
    ++status_.frames;
    lock.unlock();

    if (has_exposure_ && now >= next_exposure_read_ns_)
      read_exposure(stream, now);
    note_clock(stamp.clock);
    out = CapturedFrame{
        .format = format_,
        .bytes = stream.bytes(index),
        .sequence = step.sequence,
        .timestamp_ns = stamp.ns,
        .mark = stamp.mark,
        .exposure_ns = exposure_ns_,
        .buffer = static_cast<int>((current_.generation << kIndexBits) | buffer.index),
    };
    return CaptureResult::frame;
  }
}

void V4l2Camera::release(const CapturedFrame &frame) {
  if (frame.buffer < 0)
    return;
  const auto generation = static_cast<std::uint32_t>(frame.buffer) >> kIndexBits;
  const int index = frame.buffer & ((1 << kIndexBits) - 1);
  const std::lock_guard lock(mutex_);
  if (current_.stream && current_.generation == generation) {
    // A second or stale release (the buffer carries a newer frame) is a
    // caller bug with nothing to recover: ignored, like the file camera.
    if (!current_.stream->held(index, frame.sequence))
      return;
    current_.stream->unhold(index);
    if (!current_.stream->queue(index) && broken_.empty())
      broken_ = "VIDIOC_QBUF: " + errno_text(errno);
    return;
  }
  for (auto it = retired_.begin(); it != retired_.end(); ++it) {
    if (it->generation != generation || !it->stream->held(index, frame.sequence))
      continue;
    it->stream->unmap(index);
    if (!it->stream->holds_any())
      retired_.erase(it);
    return;
  }
}

bool V4l2Camera::reconnect(std::int64_t deadline) {
  if (!schedule_.due(base::monotonic_ns())) {
    sleep_until(std::min(deadline, schedule_.next_ns()));
    if (!schedule_.due(base::monotonic_ns()))
      return false;
  }
  std::string error;
  std::unique_ptr<CaptureStream> stream = CaptureStream::open(request_, error);
  if (stream && stream->format() != format_) {
    error = "it is back but answers " + base::describe(stream->format()) + ", not " +
            base::describe(format_);
    stream.reset();
  }
  if (!stream) {
    schedule_.failed(base::monotonic_ns());
    const std::lock_guard lock(mutex_);
    status_.detail = name_ + ": disconnected, reopening every 0.25 s; last try: " + error;
    return false;
  }
  schedule_.succeeded();
  read_exposure(*stream, base::monotonic_ns());
  clock_noted_ = false;
  generation_ = (generation_ + 1) % kGenerations;
  const std::lock_guard lock(mutex_);
  current_ = {generation_, std::move(stream)};
  ++status_.reconnects;
  status_.connected = true;
  status_.detail = name_ + ": reconnected, " + current_.stream->summary();
  return true;
}

void V4l2Camera::lose(const std::string &reason) {
  schedule_.lost(base::monotonic_ns());
  sequence_.restart();
  const std::lock_guard lock(mutex_);
  current_.stream->close_device();
  if (current_.stream->holds_any())
    retired_.push_back(std::move(current_));
  current_ = {};
  broken_.clear();
  status_.connected = false;
  status_.detail = name_ + ": disconnected (" + reason + "); reopening every 0.25 s";
}

void V4l2Camera::read_exposure(const CaptureStream &stream, std::int64_t now) {
  has_exposure_ = stream.read_exposure(exposure_ns_);
  if (!has_exposure_)
    exposure_ns_ = 0;
  next_exposure_read_ns_ = now + kExposureReadIntervalNs;
}

void V4l2Camera::note_clock(StampClock clock) {
  if (clock_noted_ && clock == clock_)
    return;
  clock_noted_ = true;
  clock_ = clock;
  if (clock == StampClock::monotonic)
    return;
  const std::lock_guard lock(mutex_);
  status_.detail += "; timestamps: " + clock_text(clock);
}

} // namespace

std::unique_ptr<CameraSource> open_v4l2_camera(const V4l2CameraOptions &options) {
  const std::string &device = options.device;
  if (device.empty())
    throw V4l2CameraError("V4L2 camera: no device named");
  if (options.format == base::PixelFormat::xrgb8888)
    throw V4l2CameraError(device + ": format: xrgb8888 is a display format; a camera gives "
                                   "yuyv, nv12, rgb24 or bgr24");
  if (options.mjpeg && options.format != base::PixelFormat::rgb24)
    throw V4l2CameraError(device + ": format: MJPEG frames are delivered decoded as rgb24, not " +
                          std::string(base::pixel_format_name(options.format)));
  base::VideoFormat wanted{options.format, options.width, options.height};
  if (const std::string reason = base::check_video_format(wanted); !reason.empty())
    throw V4l2CameraError(device + ": format: " + reason);
  if (!std::isfinite(options.fps) || options.fps < 0 ||
      (options.fps > 0 && (options.fps < 0.01 || options.fps > 1000)))
    throw V4l2CameraError(device + ": fps: " + std::to_string(options.fps) +
                          " is not 0 (the driver's rate) or 0.01 to 1000");
  if (options.buffers < 2 || options.buffers > 8)
    throw V4l2CameraError(device + ": buffers: " + std::to_string(options.buffers) +
                          " is not 2 to 8");
  StreamRequest request{device,      options.format,  options.width, options.height,
                        options.fps, options.buffers, options.mjpeg};
  std::string error;
  std::unique_ptr<CaptureStream> stream = CaptureStream::open(request, error);
  if (!stream)
    throw V4l2CameraError(device + ": " + error);
  return std::make_unique<V4l2Camera>(std::move(request), std::move(stream));
}

} // namespace camhead::hal::camera
