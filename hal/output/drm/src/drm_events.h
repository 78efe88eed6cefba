// The events a DRM file descriptor delivers on read(): a stream of
// variable-length records, each a struct drm_event header (type, length)
// followed by its body. The sink asks for one per page flip
// (DRM_EVENT_FLIP_COMPLETE, a struct drm_event_vblank whose user_data is the
// value passed to the flip); this is what libdrm's drmHandleEvent() parses.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace camhead::hal::output::drm {

struct DrmEvent {
  std::uint32_t type = 0;      // DRM_EVENT_VBLANK, DRM_EVENT_FLIP_COMPLETE, ...
  std::uint64_t user_data = 0; // for the vblank-shaped events, else 0
  std::uint32_t crtc_id = 0;   // ditto; 0 from kernels before 4.12
};

// The events in the bytes one read() returned. A record whose length is
// shorter than its header or runs past the end stops the parse (the kernel
// only ever hands over whole events, so that is a bug, not a partial read).
[[nodiscard]] std::vector<DrmEvent> parse_drm_events(std::span<const std::uint8_t> bytes);

} // namespace camhead::hal::output::drm
