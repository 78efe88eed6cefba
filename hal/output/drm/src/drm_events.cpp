// See drm_events.h.
#include "drm_events.h"

#include <cstring>

#include <drm.h>

namespace camhead::hal::output::drm {

std::vector<DrmEvent> parse_drm_events(std::span<const std::uint8_t> bytes) {
  std::vector<DrmEvent> events;
  std::size_t at = 0;
  while (bytes.size() - at >= sizeof(drm_event)) {
    drm_event header{};
    std::memcpy(&header, bytes.data() + at, sizeof header);
    if (header.length < sizeof header || header.length > bytes.size() - at)
      break;
    DrmEvent event;
    event.type = header.type;
    const bool vblank_shaped =
        header.type == DRM_EVENT_VBLANK || header.type == DRM_EVENT_FLIP_COMPLETE;
    if (vblank_shaped && header.length >= sizeof(drm_event_vblank)) {
      drm_event_vblank body{};
      std::memcpy(&body, bytes.data() + at, sizeof body);
      event.user_data = body.user_data;
      event.crtc_id = body.crtc_id;
    }
    events.push_back(event);
    at += header.length;
  }
  return events;
}

} // namespace camhead::hal::output::drm
