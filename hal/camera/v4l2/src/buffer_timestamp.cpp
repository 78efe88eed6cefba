// See buffer_timestamp.h.
#include "buffer_timestamp.h"

#include <linux/videodev2.h>

namespace camhead::hal::camera {
namespace {

constexpr std::int64_t kWindowNs = 10'000'000'000;
// A stamp a little after "now" is the same clock, not the future: vivid
// stamps the end of a frame a frame period ahead of handing it over.
constexpr std::int64_t kAheadNs = 1'000'000'000;

TimestampMark mark_of(std::uint32_t flags) {
  return (flags & V4L2_BUF_FLAG_TSTAMP_SRC_MASK) == V4L2_BUF_FLAG_TSTAMP_SRC_SOE
             ? TimestampMark::start_of_exposure
             : TimestampMark::end_of_frame;
}

bool near(std::int64_t stamp, std::int64_t now) {
  return stamp > now - kWindowNs && stamp <= now + kAheadNs;
}

} // namespace

BufferStamp buffer_stamp(std::uint32_t flags, std::int64_t stamp_ns, const base::ClockPair &now) {
  const std::uint32_t type = flags & V4L2_BUF_FLAG_TIMESTAMP_MASK;
  if (stamp_ns > 0 && type == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC)
    return {stamp_ns, mark_of(flags), StampClock::monotonic};
  if (stamp_ns > 0 && near(stamp_ns, now.monotonic_ns))
    return {stamp_ns, mark_of(flags), StampClock::judged_monotonic};
  if (stamp_ns > 0 && now.known() && near(stamp_ns, now.realtime_ns))
    return {now.monotonic_of(stamp_ns), mark_of(flags), StampClock::converted_realtime};
  return {now.monotonic_ns, TimestampMark::end_of_frame, StampClock::dequeue_time};
}

std::string clock_text(StampClock clock) {
  switch (clock) {
  case StampClock::monotonic:
    return "the driver's, on CLOCK_MONOTONIC";
  case StampClock::judged_monotonic:
    return "the driver's, which names no clock but matches CLOCK_MONOTONIC";
  case StampClock::converted_realtime:
    return "the driver's on the wall clock, converted to CLOCK_MONOTONIC";
  case StampClock::dequeue_time:
    return "the time of dequeue (the driver's stamps are on no clock camhead knows)";
  }
  return "?";
}

} // namespace camhead::hal::camera
