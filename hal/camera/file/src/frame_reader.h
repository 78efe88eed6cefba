// One kind of file the file camera plays (Y4M, PNG sequence), behind the
// pacing and buffering that file_camera.cpp does for all of them. A reader
// checks everything it can when it is made, throwing FileCameraError, and
// after that reports ends and errors as values.
//
// Thread safety: none; the capture thread owns the reader.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "camhead/base/video_format.h"
#include "camhead/hal/camera/file/file_camera.h"

namespace camhead::hal::camera {

class FrameReader {
public:
  virtual ~FrameReader() = default;

  [[nodiscard]] virtual base::VideoFormat format() const = 0;

  // The rate the file states; 0 when it states none.
  [[nodiscard]] virtual std::int64_t native_interval_ns() const = 0;

  enum class Read { frame, end, error };

  // The next frame into `frame` (frame_bytes(format()) bytes). On `error`,
  // `error` is the whole message, "FILE:frame N: REASON", and the reader is
  // not used again.
  [[nodiscard]] virtual Read read(std::span<std::uint8_t> frame, std::string &error) = 0;

  // Back to the first frame, for looping; false with `error` if that fails.
  [[nodiscard]] virtual bool rewind(std::string &error) = 0;
};

// The size a caller needs (FileCameraOptions::width, height; 0 x 0: any).
struct WantedSize {
  int width = 0, height = 0;
};

// Throws FileCameraError "FILE: size: ..." unless a frame of `width` x
// `height` is what `wanted` asks for.
inline void check_size(const std::string &file, int width, int height, WantedSize wanted) {
  if ((wanted.width == 0 && wanted.height == 0) ||
      (width == wanted.width && height == wanted.height))
    return;
  throw FileCameraError(file + ": size: its frames are " + std::to_string(width) + "x" +
                        std::to_string(height) + ", the camera's are to be " +
                        std::to_string(wanted.width) + "x" + std::to_string(wanted.height));
}

// A Y4M file. `rate_given`: the caller has its own rate, so a header without
// one (no F, or F0:0) is fine.
[[nodiscard]] std::unique_ptr<FrameReader> open_y4m_reader(const std::filesystem::path &path,
                                                           bool rate_given, WantedSize wanted = {});

// A pattern, a folder of PNGs or one PNG (file_camera.h).
[[nodiscard]] std::unique_ptr<FrameReader>
open_png_sequence_reader(const std::filesystem::path &path, WantedSize wanted = {});

} // namespace camhead::hal::camera
