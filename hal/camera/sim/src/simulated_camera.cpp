#include "camhead/hal/camera/sim/simulated_camera.h"

#include <cmath>
#include <ctime>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/base/monotonic_clock.h"

namespace camhead::hal::camera {
namespace {

void sleep_until_ns(std::int64_t t_ns) {
  timespec ts{};
  ts.tv_sec = time_t(t_ns / 1'000'000'000);
  ts.tv_nsec = long(t_ns % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

class SimulatedCamera final : public CameraSource {
public:
  SimulatedCamera(SimulatedCameraOptions options, FrameGenerator generator)
      : options_(options), generator_(std::move(generator)),
        interval_ns_(std::int64_t(std::llround(1e9 / options.fps))),
        exposure_ns_(options.exposure_ns > 0 ? options.exposure_ns : interval_ns_ / 2) {
    const std::size_t bytes = base::frame_bytes(options_.format);
    buffers_.assign(std::size_t(options_.buffers), std::vector<std::uint8_t>(bytes));
    held_.assign(std::size_t(options_.buffers), false);
    status_.connected = true;
    if (options_.realtime && options_.warm_up_frames > 0) {
      const std::int64_t grid = base::monotonic_ns();
      grid_ns_ = grid;
      for (std::uint64_t k = 0; k < options_.warm_up_frames; ++k) {
        generator_(grid + std::int64_t(k) * interval_ns_, exposure_ns_, buffers_.front());
        if (options_.warm_up_progress)
          options_.warm_up_progress(k + 1, options_.warm_up_frames);
      }
    }
  }

  std::string name() const override { return "sim " + base::describe(options_.format); }
  base::VideoFormat format() const override { return options_.format; }
  std::int64_t frame_interval_ns() const override { return interval_ns_; }

  CaptureResult wait_frame(std::chrono::milliseconds timeout, CapturedFrame &out) override {
    const std::int64_t now = base::monotonic_ns();
    const std::int64_t deadline = now + std::int64_t(timeout.count()) * 1'000'000;
    if (start_ns_ == 0) // on the warm-up's grid, if there was one: its next instant
      start_ns_ =
          grid_ns_ ? *grid_ns_ + (now - *grid_ns_ + interval_ns_ - 1) / interval_ns_ * interval_ns_
                   : now;
    if (gone_until_ns_ != 0) {
      if (now < gone_until_ns_) {
        sleep_until_ns(std::min(deadline, gone_until_ns_));
        return options_.disconnect_silently ? CaptureResult::timeout : CaptureResult::disconnected;
      }
      // Back: a camera that was re-plugged starts a new stream.
      gone_until_ns_ = 0;
      if (!options_.disconnect_silently)
        set_connected(true, "back after a simulated disconnect");
      if (options_.realtime)
        next_ = frame_due_after(base::monotonic_ns());
    }
    const int buffer = free_buffer();
    if (buffer < 0) {
      sleep_until_ns(deadline);
      return CaptureResult::timeout;
    }
    if (options_.realtime) {
      // The newest exposure that is complete by now; older untaken ones are
      // lost, as a camera overwrites what nobody dequeued.
      const std::int64_t complete = (now - start_ns_) / interval_ns_ - 1;
      if (complete > std::int64_t(next_)) {
        count_dropped(std::uint64_t(complete) - next_);
        next_ = std::uint64_t(complete);
      }
      const std::int64_t due = exposure_start(next_) + exposure_ns_;
      if (due > deadline) {
        sleep_until_ns(deadline);
        return CaptureResult::timeout;
      }
      sleep_until_ns(due);
    }
    if (options_.disconnect_after_frames && delivered_ == *options_.disconnect_after_frames &&
        !fault_done_) {
      fault_done_ = true;
      gone_until_ns_ = base::monotonic_ns() + std::int64_t(options_.disconnect_s * 1e9);
      if (options_.disconnect_silently)
        return CaptureResult::timeout;
      set_connected(false,
                    "simulated disconnect for " + std::to_string(options_.disconnect_s) + " s");
      return CaptureResult::disconnected;
    }
    std::vector<std::uint8_t> &bytes = buffers_[std::size_t(buffer)];
    const std::int64_t start = exposure_start(next_);
    generator_(start, exposure_ns_, bytes);
    out = CapturedFrame{.format = options_.format,
                        .bytes = bytes,
                        .sequence = next_,
                        .timestamp_ns = start,
                        .mark = TimestampMark::start_of_exposure,
                        .exposure_ns = exposure_ns_,
                        .buffer = buffer};
    ++next_;
    ++delivered_;
    {
      std::lock_guard lock(mutex_);
      held_[std::size_t(buffer)] = true;
      ++status_.frames;
    }
    return CaptureResult::frame;
  }

  void release(const CapturedFrame &frame) override {
    std::lock_guard lock(mutex_);
    if (frame.buffer >= 0 && std::size_t(frame.buffer) < held_.size())
      held_[std::size_t(frame.buffer)] = false;
  }

  CameraStatus status() const override {
    std::lock_guard lock(mutex_);
    return status_;
  }

private:
  std::int64_t exposure_start(std::uint64_t k) const {
    return start_ns_ + std::int64_t(k) * interval_ns_;
  }

  // The first frame whose exposure starts at or after t.
  std::uint64_t frame_due_after(std::int64_t t) const {
    return std::uint64_t((t - start_ns_ + interval_ns_ - 1) / interval_ns_);
  }

  int free_buffer() const {
    std::lock_guard lock(mutex_);
    for (std::size_t i = 0; i < held_.size(); ++i)
      if (!held_[i])
        return int(i);
    return -1;
  }

  void count_dropped(std::uint64_t n) {
    std::lock_guard lock(mutex_);
    status_.dropped += n;
  }

  void set_connected(bool connected, std::string detail) {
    std::lock_guard lock(mutex_);
    if (connected && !status_.connected)
      ++status_.reconnects;
    status_.connected = connected;
    status_.detail = std::move(detail);
  }

  const SimulatedCameraOptions options_;
  const FrameGenerator generator_;
  const std::int64_t interval_ns_;
  const std::int64_t exposure_ns_;
  std::vector<std::vector<std::uint8_t>> buffers_;
  std::int64_t start_ns_ = 0;
  std::optional<std::int64_t> grid_ns_; // the warm-up's first exposure
  std::uint64_t next_ = 0;              // sequence number of the next frame
  std::uint64_t delivered_ = 0;         // for the fault option
  std::int64_t gone_until_ns_ = 0;
  bool fault_done_ = false;
  mutable std::mutex mutex_; // guards held_ and status_
  std::vector<bool> held_;
  CameraStatus status_;
};

} // namespace

std::unique_ptr<CameraSource> open_simulated_camera(SimulatedCameraOptions options,
                                                    FrameGenerator generator) {
  if (std::string reason = base::check_video_format(options.format); !reason.empty())
    throw std::invalid_argument("simulated camera: format: " + reason);
  if (!(options.fps > 0.0) || !std::isfinite(options.fps) || options.fps > 1000.0)
    throw std::invalid_argument("simulated camera: fps: must be > 0 and at most 1000, not " +
                                std::to_string(options.fps));
  if (options.buffers < 2 || options.buffers > 32)
    throw std::invalid_argument("simulated camera: buffers: must be 2 to 32, not " +
                                std::to_string(options.buffers));
  if (!generator)
    throw std::invalid_argument("simulated camera: no frame generator");
  return std::make_unique<SimulatedCamera>(options, std::move(generator));
}

} // namespace camhead::hal::camera
