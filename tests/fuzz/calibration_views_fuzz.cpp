// libFuzzer target for the views `camhead calibrate camera` reads
// (pipeline/tracking/calibration_views.h), as a Y4M video: the input is the
// whole file, written where the reader opens it (a .y4m in the temporary
// folder; the reader goes by the name). It must be refused with a
// CalibrationViewError naming the file, or give views each of a whole luma
// plane; PNG views go through base/png_reader.h, which png_fuzz covers.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "fuzz_check.h"
#include "tracking/calibration_views.h"

namespace {

using camhead::fuzz::check;
namespace fs = std::filesystem;

// The file each input is written to, removed when the fuzzer exits.
struct Scratch {
  fs::path path =
      fs::temp_directory_path() / ("calibration_views_fuzz_" + std::to_string(::getpid()) + ".y4m");
  ~Scratch() {
    std::error_code ec;
    fs::remove(path, ec);
  }
};

const fs::path &scratch() {
  static const Scratch file;
  return file.path;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  {
    std::ofstream out(scratch(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char *>(data), std::streamsize(size));
    check(bool(out));
  }
  try {
    const std::vector<camhead::pipeline::CalibrationPicture> views =
        camhead::pipeline::read_calibration_views({scratch()}, 5);
    check(!views.empty() && views.size() <= 5);
    for (const camhead::pipeline::CalibrationPicture &v : views)
      check(v.width > 0 && v.height > 0 &&
            v.luma.size() == std::size_t(v.width) * std::size_t(v.height));
  } catch (const camhead::pipeline::CalibrationViewError &e) {
    check(std::string(e.what()).rfind(scratch().string() + ": ", 0) == 0);
  }
  return 0;
}
