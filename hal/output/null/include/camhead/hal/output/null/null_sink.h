// A FrameSink that counts frames and discards them. It lends one buffer of
// frame_bytes(format) and never fails once open, so that a benchmark's
// output costs nothing but the frame the renderer writes.
//
// Thread safety: as FrameSink.
#pragma once

#include <memory>

#include "camhead/hal/output/frame_sink.h"

namespace camhead::hal::output {

// Throws std::invalid_argument ("null sink: REASON") for a format that
// check_video_format refuses, since its buffer could not be sized.
[[nodiscard]] std::unique_ptr<FrameSink> open_null_sink(base::VideoFormat format);

} // namespace camhead::hal::output
