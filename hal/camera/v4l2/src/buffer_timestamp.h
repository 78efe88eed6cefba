// A dequeued buffer's timestamp on CLOCK_MONOTONIC. Drivers that set
// V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC (vb2 drivers: uvcvideo, vivid) are
// taken at their word. Others do not say: v4l2loopback 0.12.7 stamps with
// the monotonic clock but flags nothing, old out-of-tree drivers used the
// wall clock, and a COPY stamp is whatever the writer put there. Those are
// judged by value: within 10 s before (or 1 s after) now on the monotonic clock it is
// monotonic; within 10 s of the wall clock it is converted; anything else
// (0, garbage) is replaced by the time of the dequeue, which is after the
// end of the frame.
#pragma once

#include <cstdint>
#include <string>

#include "camhead/base/realtime_stamp.h"
#include "camhead/hal/camera/camera_source.h"

namespace camhead::hal::camera {

enum class StampClock {
  monotonic,          // the driver says CLOCK_MONOTONIC
  judged_monotonic,   // the driver does not say; the value is on CLOCK_MONOTONIC
  converted_realtime, // the driver does not say; the value is on the wall clock
  dequeue_time,       // no usable stamp: the time it was dequeued
};

struct BufferStamp {
  std::int64_t ns = 0; // CLOCK_MONOTONIC
  TimestampMark mark = TimestampMark::end_of_frame;
  StampClock clock = StampClock::monotonic;
};

// `flags` of the v4l2_buffer and its timestamp in ns; `now`, both clocks
// read just after the dequeue (realtime_stamp.h). Where `now` knows no
// offset between them, no stamp is taken for a wall-clock one.
[[nodiscard]] BufferStamp buffer_stamp(std::uint32_t flags, std::int64_t stamp_ns,
                                       const base::ClockPair &now);

// For status lines: "the driver's CLOCK_MONOTONIC", ...
[[nodiscard]] std::string clock_text(StampClock clock);

} // namespace camhead::hal::camera
