// Camera rays of a camhead frame traced by Embree: the kernel's own
// camera_ray() makes them (cpu_kernel.h, renderer/src), so Embree and camhead
// trace the same rays ray for ray.
#pragma once

#include <cstdint>

#include "cpu_kernel.h" // renderer/src: the kernel as C++
#include "embree_scene.h"

namespace camhead::bench {

enum class Mode { single, packet16, stream };
[[nodiscard]] const char *mode_name(Mode mode);

struct EmbreeFrame {
  double wall_s = 0.0;
  double trace_s = 0.0; // in Embree calls and packet set-up, summed over threads
  std::uint64_t hits = 0;
};

// One frame: every camera ray of kernel.frame (all pixels, all samples),
// closest hit only, in 4 x 4 pixel blocks handed out to `threads` threads.
// The kernel's functions only read it, so the threads share one CpuKernel
// (its member functions are not const only because GLSL has no const).
[[nodiscard]] EmbreeFrame embree_frame(RTCScene scene, renderer::cpu::CpuKernel &kernel, Mode mode,
                                       int threads);

// Fraction of the camera rays of every `step`-th pixel (in x and y), all
// samples, on which Embree and camhead's closest_hit() agree: both miss, or
// both hit at the same distance (1e-3 relative).
[[nodiscard]] double hit_agreement(RTCScene scene, renderer::cpu::CpuKernel &kernel, int step);

} // namespace camhead::bench
