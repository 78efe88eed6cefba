// When `camhead run` may tell systemd's watchdog that it is alive
// (WATCHDOG=1, service_notifier.h): only while its output really advances.
// A main thread that still runs proves nothing: a render thread stuck in a
// driver leaves the output thread repeating the last composite, a lost GPU
// leaves it sending placeholders, a stuck output thread sends nothing, and
// each of those should get the service restarted.
#pragma once

#include <cstdint>

namespace camhead::pipeline {

// What the output has done so far (run_counters.h).
struct OutputProgress {
  std::uint64_t composites = 0; // rendered frames sent
  std::uint64_t placeholders = 0;
  bool camera_lost = false;
  bool renderer_lost = false;
};

// Alive between `before` and `now`: new composites, or new placeholders
// while the camera is away and the renderer is not lost (waiting for a
// camera is what the service should do; it is not stuck).
[[nodiscard]] bool output_advanced(const OutputProgress &before, const OutputProgress &now);

} // namespace camhead::pipeline
