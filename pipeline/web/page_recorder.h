// The operator page's record button: what an output gets (the composites,
// and the repeats and placeholders that keep its time) written to a Y4M
// file while it is on, as the `file:PATH.y4m` output writes one. The page's
// thread opens the file (so no frame waits for the disk's open or the
// folder's creation) and hands the sink to the output thread, which writes
// each composite it sends anyway; to stop, the output thread lets go of
// the sink at its next frame and the page's thread closes it (the file is
// renamed into place then, as every camhead file is, whole or not at all).
//
// Thread safety: submit() from the output thread; the rest from the page's.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "camhead/base/video_format.h"
#include "camhead/hal/output/frame_sink.h"

namespace camhead::pipeline::web {

class PageRecorder {
public:
  // Takes are written into `folder` (made when the first starts), as
  // `format` (yuyv or nv12: what Y4M takes; anything else and start()
  // says the run has no output to record) at `fps`.
  PageRecorder(std::filesystem::path folder, std::optional<base::VideoFormat> format, double fps);
  ~PageRecorder(); // a take still running is closed whole

  // Output thread: a frame sent to the outputs, in `format`.
  void submit(std::span<const std::uint8_t> frame, std::int64_t capture_ns);

  // Page thread. Starts a take named by the time; its path, or an error.
  struct Started {
    std::filesystem::path file;
    std::string error;
  };
  Started start();
  // Ends the take (waits up to `wait_s` for the output thread to let go of
  // it: one frame, or the half second after which the output repeats).
  // The file and the frames it holds, or an error.
  struct Stopped {
    std::filesystem::path file;
    std::uint64_t frames = 0;
    std::string error;
  };
  Stopped stop(double wait_s = 2.0);
  // The take being written, if any, and its frames so far.
  [[nodiscard]] std::optional<std::filesystem::path> file() const;
  [[nodiscard]] std::uint64_t frames() const { return frames_.load(std::memory_order_relaxed); }

private:
  std::filesystem::path folder_;
  std::optional<base::VideoFormat> format_;
  double fps_;
  std::unique_ptr<hal::output::FrameSink> sink_; // the page thread's, while no take runs on it
  std::filesystem::path file_;
  // The take the output thread writes to; null when none. The output
  // thread sets `released_` once it has stopped touching it.
  std::atomic<hal::output::FrameSink *> active_{nullptr};
  std::atomic<bool> stopping_{false}, released_{true};
  std::atomic<std::uint64_t> frames_{0}, failed_{0};
};

} // namespace camhead::pipeline::web
