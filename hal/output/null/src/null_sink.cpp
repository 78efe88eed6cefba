// See null_sink.h.
#include "camhead/hal/output/null/null_sink.h"

#include <atomic>
#include <stdexcept>

namespace camhead::hal::output {
namespace {

class NullSink final : public FrameSink {
public:
  explicit NullSink(base::VideoFormat format) : format_(format) {}

  std::string name() const override { return "null"; }
  base::VideoFormat format() const override { return format_; }
  bool submit(std::span<const std::uint8_t> frame, std::int64_t) override {
    if (!wrong_frame_size(frame, format_).empty())
      return false;
    frames_.fetch_add(1, std::memory_order_relaxed);
    return true;
  }

  bool close() override {
    closed_.store(true, std::memory_order_relaxed);
    return true;
  }

  SinkStatus status() const override {
    SinkStatus s;
    s.frames = frames_.load(std::memory_order_relaxed);
    s.connected = !closed_.load(std::memory_order_relaxed);
    s.detail = "null: " + std::to_string(s.frames) + " frames discarded";
    return s;
  }

private:
  const base::VideoFormat format_;
  // Atomics: status() may come from another thread than submit().
  std::atomic<std::uint64_t> frames_{0};
  std::atomic<bool> closed_{false};
};

} // namespace

std::unique_ptr<FrameSink> open_null_sink(base::VideoFormat format) {
  const std::string reason = base::check_video_format(format);
  if (!reason.empty())
    throw std::invalid_argument("null sink: " + reason);
  return std::make_unique<NullSink>(format);
}

} // namespace camhead::hal::output
