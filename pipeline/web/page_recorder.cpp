#include "page_recorder.h"

#include <chrono>
#include <ctime>
#include <system_error>
#include <thread>

#include "camhead/hal/output/file/file_sink.h"

namespace camhead::pipeline::web {
namespace {

// take-20261204-193012.y4m, in local time: what an operator reads on a clock.
std::string take_name() {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char name[64];
  std::strftime(name, sizeof name, "take-%Y%m%d-%H%M%S.y4m", &local);
  return name;
}

} // namespace

PageRecorder::PageRecorder(std::filesystem::path folder, std::optional<base::VideoFormat> format,
                           double fps)
    : folder_(std::filesystem::absolute(folder)), format_(format), fps_(fps) {}

PageRecorder::~PageRecorder() {
  // The output thread has ended by now (the run joins it first).
  if (sink_)
    (void)sink_->close();
}

void PageRecorder::submit(std::span<const std::uint8_t> frame, std::int64_t capture_ns) {
  hal::output::FrameSink *sink = active_.load(std::memory_order_acquire);
  if (sink == nullptr)
    return;
  if (stopping_.load(std::memory_order_acquire)) {
    active_.store(nullptr, std::memory_order_relaxed);
    released_.store(true, std::memory_order_release);
    return;
  }
  if (sink->submit(frame, capture_ns))
    frames_.fetch_add(1, std::memory_order_relaxed);
  else
    failed_.fetch_add(1, std::memory_order_relaxed);
}

PageRecorder::Started PageRecorder::start() {
  if (sink_)
    return {file_, "already recording to " + file_.string()};
  if (!format_)
    return {{}, "no output of this run is in a format Y4M takes (yuyv or nv12)"};
  std::error_code error;
  std::filesystem::create_directories(folder_, error);
  if (error)
    return {{}, folder_.string() + ": " + error.message()};
  std::filesystem::path file = folder_ / take_name();
  for (int n = 2; std::filesystem::exists(file); ++n) // two takes in one second
    file = folder_ / (file.stem().string().substr(0, 20) + "-" + std::to_string(n) + ".y4m");
  try {
    sink_ = hal::output::open_y4m_sink(file, *format_, fps_);
  } catch (const std::exception &e) {
    return {{}, e.what()};
  }
  file_ = file;
  frames_ = 0;
  failed_ = 0;
  stopping_ = false;
  released_ = false;
  active_.store(sink_.get(), std::memory_order_release);
  return {file_, {}};
}

PageRecorder::Stopped PageRecorder::stop(double wait_s) {
  if (!sink_)
    return {{}, 0, "not recording"};
  stopping_.store(true, std::memory_order_release);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
  while (!released_.load(std::memory_order_acquire) && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  if (!released_.load(std::memory_order_acquire))
    return {file_, frames(),
            "the output thread sent no frame for " + std::to_string(wait_s) +
                " s; the take goes on"};
  Stopped out{file_, frames(), {}};
  if (!sink_->close())
    out.error = file_.string() + ": " + sink_->status().detail;
  else if (failed_ > 0)
    out.error =
        std::to_string(failed_.load()) + " frames could not be written: " + sink_->status().detail;
  sink_.reset();
  return out;
}

std::optional<std::filesystem::path> PageRecorder::file() const {
  if (!sink_)
    return std::nullopt;
  return file_;
}

} // namespace camhead::pipeline::web
