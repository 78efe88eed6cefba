// The pictures `camhead calibrate camera` fits a camera to, as luma planes
// (luma.h's weights): PNG files (8 or 16 bits, any colour type), one view
// each, and Y4M videos, whose frames are spread evenly over the views
// allowed, their codes in the range their header states. Nothing is read
// past a file's own size; errors name the file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "tracking/marker_tracker.h"

namespace camhead::pipeline {

class CalibrationViewError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

struct CalibrationPicture {
  std::string name; // "IMG_0001.png", "take.y4m frame 40"
  int width = 0, height = 0;
  std::vector<std::uint8_t> luma; // rows packed
  // Its codes span 16-235: a Y4M video's, unless its header says
  // XCOLORRANGE=FULL (a PNG's span 0-255).
  bool limited_range = false;

  [[nodiscard]] LumaImage image() const {
    return {luma.data(), width, height, width, limited_range};
  }
};

// Every PNG of `files`, and at most `frames_per_video` frames of each Y4M
// (every frame of a shorter one). Throws CalibrationViewError.
[[nodiscard]] std::vector<CalibrationPicture>
read_calibration_views(const std::vector<std::filesystem::path> &files,
                       std::size_t frames_per_video);

} // namespace camhead::pipeline
