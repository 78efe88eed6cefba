// See reconnect_schedule.h.
#include "camhead/hal/v4l2/reconnect_schedule.h"

namespace camhead::hal::v4l2 {

void ReconnectSchedule::lost(std::int64_t now_ns) {
  waiting_ = true;
  next_ns_ = now_ns + interval_ns_;
  failures_ = 0;
}

bool ReconnectSchedule::due(std::int64_t now_ns) const {
  return waiting_ && now_ns >= next_ns_;
}

void ReconnectSchedule::failed(std::int64_t now_ns) {
  ++failures_;
  next_ns_ = now_ns + interval_ns_;
}

void ReconnectSchedule::succeeded() {
  waiting_ = false;
  failures_ = 0;
}

} // namespace camhead::hal::v4l2
