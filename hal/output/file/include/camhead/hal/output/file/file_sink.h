// Outputs to files: a Y4M file (what ffmpeg, mpv and x264 read) and a PNG
// sequence. Neither ever leaves a half-written file under its final name:
// data goes to NAME.partial in the same folder and is renamed over NAME when
// complete, so a reader sees the old file or the new one, never a mix.
//
// Y4M: everything is checked and the header written at open, so that an
// unwritable folder fails there and not at the first frame. Frames are
// appended at submit(); the file is synced and renamed into place by
// close(). A sink destroyed without close() removes its partial file and
// leaves PATH as it was. A frame whose write fails (a full disk) is cut off
// again, so that the file stays whole up to the last good frame; close()
// still puts that in place. PATH must be a regular file or not exist: a
// device node, FIFO or folder is refused at open (renaming over /dev/null
// would replace the device). A symbolic link is followed: the file it names
// is replaced and the link kept. "-" (standard output) is refused rather
// than taken as a file named "-". capture_ns is not stored (Y4M has no
// stamps).
//
// PNG sequence: frame k (from 0) goes to the pattern's file k, each through
// its own NAME.partial and rename; numbers count frames written, so a failed
// frame leaves no gap for a reader that stops at the first missing number.
// The folder is created if missing. Frames are not synced one by one
// (that would cost more than encoding them).
//
// Thread safety: as FrameSink.
#pragma once

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "camhead/hal/output/frame_sink.h"

namespace camhead::hal::output {

// "PATH: REASON", thrown by the open functions only.
class FileSinkError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// `format` is yuyv (written as C422) or nv12 (C420mpeg2: nv12's siting), any
// stride; XCOLORRANGE follows its range. `fps`: 0.01 to 1000, written as a
// ratio (29.97 as 30000:1001).
[[nodiscard]] std::unique_ptr<FrameSink> open_y4m_sink(const std::filesystem::path &path,
                                                       base::VideoFormat format, double fps);

// `pattern`: exactly one %d-style conversion ("out/%05d.png"); `format`:
// rgb24, any stride.
[[nodiscard]] std::unique_ptr<FrameSink> open_png_sequence_sink(const std::string &pattern,
                                                                base::VideoFormat format);

} // namespace camhead::hal::output
