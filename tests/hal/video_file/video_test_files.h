// Scratch folders, generated frames and small file helpers for the hal_video
// tests.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

#include "camhead/base/video_format.h"
#include "camhead/hal/camera/camera_source.h"
#include "camhead/hal/output/frame_sink.h"

#include <gtest/gtest.h>

namespace camhead::test {

// A fresh folder for one test, removed with everything in it afterwards.
class ScratchDir {
public:
  ScratchDir() {
    const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("camhead_hal_video_" + std::to_string(::getpid()) + "_" + info->test_suite_name() +
             "_" + info->name());
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir &) = delete;
  ScratchDir &operator=(const ScratchDir &) = delete;

  [[nodiscard]] std::filesystem::path operator/(std::string_view name) const {
    return path_ / name;
  }
  [[nodiscard]] const std::filesystem::path &path() const { return path_; }

private:
  std::filesystem::path path_;
};

[[nodiscard]] inline base::VideoFormat
make_format(base::PixelFormat pixel, int width, int height,
            base::ColorRange range = base::ColorRange::limited) {
  base::VideoFormat format;
  format.pixel = pixel;
  format.width = width;
  format.height = height;
  format.range = range;
  return format;
}

// Bytes that differ from frame to frame and from byte to byte and take every
// value, so a swapped plane, a shifted row or a repeated frame shows.
[[nodiscard]] inline std::vector<std::uint8_t> generated_frame(const base::VideoFormat &format,
                                                               int seed) {
  std::vector<std::uint8_t> bytes(base::frame_bytes(format));
  for (std::size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = static_cast<std::uint8_t>(i * 37 + (i >> 8) * 11 + std::size_t(seed) * 101 + 7);
  return bytes;
}

[[nodiscard]] inline std::string read_text(const std::filesystem::path &path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_text(const std::filesystem::path &path, std::string_view text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

// Submits `frames` through `sink` and closes it, asserting every step.
inline void write_all(hal::output::FrameSink &sink,
                      const std::vector<std::vector<std::uint8_t>> &frames) {
  for (const auto &frame : frames)
    ASSERT_TRUE(sink.submit(frame, 0)) << sink.status().detail;
  ASSERT_TRUE(sink.close()) << sink.status().detail;
}

// Every frame up to `ended`, copied out and released at once.
[[nodiscard]] inline std::vector<std::vector<std::uint8_t>>
read_all(hal::camera::CameraSource &camera, std::size_t limit = 1000) {
  std::vector<std::vector<std::uint8_t>> frames;
  hal::camera::CapturedFrame frame;
  while (frames.size() < limit) {
    const auto result = camera.wait_frame(std::chrono::milliseconds(1000), frame);
    if (result != hal::camera::CaptureResult::frame)
      break;
    frames.emplace_back(frame.bytes.begin(), frame.bytes.end());
    camera.release(frame);
  }
  return frames;
}

} // namespace camhead::test
