// The influence region: the pixels of a frame where the virtual objects can
// change the composite, so that a frame costs what the virtual objects
// touch. Everywhere else I_m == I_r and M == 0, so equation 4 returns the
// camera image bit for bit (kernel.glsl, resolve_pixel) and nothing needs to
// be traced.
//
// The region is conservative: every pixel any camera ray of which can reach
// a virtual object, directly or through real mirrors and glass, or can land
// on a real surface that a virtual object shadows from some light. It is
// built in world space from boxes and cones and projected through the thin
// lens, the blur circle at each depth included; influence_region.cpp says
// how. A real proxy in front of a virtual object does not shrink it.
//
// Tracing the region only gives the same composite as tracing the whole
// frame, bit for bit, with the same seeds (tests/renderer/
// influence_region_test.cpp); the other layers (I_m, I_r, M, depth) are not
// computed outside it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/gpu_layout.h"

namespace camhead::renderer {

// Pixels [x0, x1) x [y0, y1).
struct PixelRect {
  std::uint32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  [[nodiscard]] std::uint64_t pixels() const { return std::uint64_t(x1 - x0) * (y1 - y0); }
  bool operator==(const PixelRect &) const = default;
};

struct InfluenceRegion {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  // Disjoint rectangles of whole tiles (CAMHEAD_TILE_X x CAMHEAD_TILE_Y, cut
  // at the image's edge), top to bottom: what the GPU dispatches.
  std::vector<PixelRect> rects;

  [[nodiscard]] std::uint64_t pixels() const;
  [[nodiscard]] bool whole_frame() const { return pixels() == std::uint64_t(width) * height; }
  [[nodiscard]] double fraction() const {
    return width * height == 0 ? 0.0 : double(pixels()) / (double(width) * height);
  }
};

// The most rectangles a region of a width x height frame holds (one per
// tile), for storage that copies regions without growing.
[[nodiscard]] std::size_t max_region_rects(std::uint32_t width, std::uint32_t height);

// Every pixel of a width x height frame: what tracing without a region does.
[[nodiscard]] InfluenceRegion whole_frame_region(std::uint32_t width, std::uint32_t height);

// The regions of one scene's frames, as the live path builds them: the
// world-space part (influence_region.cpp, step 1) depends on the scene
// alone and is built once; build() projects it through each frame's lens
// into storage the builder keeps. After the first frame of a size, a frame
// allocates nothing (tests/renderer/frame_allocations_test.cpp), unless the
// camera goes further from the scene's origin than the scene's objects and
// than it has been: the margin grows with that distance, and step 1 is
// built again, with a quarter more room.
// `scene` must outlive the builder.
class InfluenceRegionBuilder {
public:
  explicit InfluenceRegionBuilder(const CompiledScene &scene);
  ~InfluenceRegionBuilder();
  InfluenceRegionBuilder(const InfluenceRegionBuilder &) = delete;
  InfluenceRegionBuilder &operator=(const InfluenceRegionBuilder &) = delete;

  // The region of `frame` (world coordinates, as make_frame_params() gives
  // them). Without a plate (frame.image.z == 0) the composite is I_m, which
  // needs every pixel: the whole frame. Valid until the next call.
  [[nodiscard]] const InfluenceRegion &build(const gpu::FrameParams &frame);
  // Every pixel, in the same storage.
  [[nodiscard]] const InfluenceRegion &whole_frame(std::uint32_t width, std::uint32_t height);
  // No pixel (a plate-only frame: frame_renderer.h), in the same storage.
  [[nodiscard]] const InfluenceRegion &none(std::uint32_t width, std::uint32_t height);

private:
  struct State;
  std::unique_ptr<State> state_;
};

// The region of one frame, by a builder of its own.
[[nodiscard]] InfluenceRegion influence_region(const CompiledScene &scene,
                                               const gpu::FrameParams &frame);

} // namespace camhead::renderer
