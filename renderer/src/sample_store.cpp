#include "sample_store.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>

#include "camhead/renderer/frame_settings.h"

namespace camhead::renderer::cpu {
namespace {

bool same(const gpu::vec4 &a, const gpu::vec4 &b) {
  return a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w;
}

bool finite(const gpu::vec4 &v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

} // namespace

bool same_view(const gpu::FrameParams &a, const gpu::FrameParams &b) {
  return same(a.cam_position, b.cam_position) && same(a.cam_right, b.cam_right) &&
         same(a.cam_up, b.cam_up) && same(a.cam_forward, b.cam_forward) &&
         same(a.world_color, b.world_color) && a.image.x == b.image.x && a.image.y == b.image.y &&
         a.image.w == b.image.w && a.tracing.x == b.tracing.x && a.lens.w == b.lens.w &&
         // The principal point, fy / fx and the distortion; the image scale
         // (lens.z) may breathe.
         has_lens_model(a) == has_lens_model(b) &&
         (!has_lens_model(a) ||
          (same(a.projection, b.projection) && same(a.distortion, b.distortion)));
}

bool reprojectable(const gpu::FrameParams &from, const gpu::FrameParams &to) {
  return same_view(from, to) && from.lens.w == 1.0f && finite(from.lens) && finite(to.lens) &&
         from.lens.y > 0.0f && to.lens.y > 0.0f && from.lens.z > 0.0f && to.lens.z > 0.0f &&
         to.lens.x >= 0.0f && to.lens.x <= from.lens.x;
}

void SampleStore::reserve(std::size_t capacity, std::uint32_t width, std::uint32_t height) {
  width_ = width;
  height_ = height;
  tiles_x_ = (width + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X;
  tiles_y_ = (height + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y;
  samples_.assign(capacity, StoredSample{});
  for (Frame &frame : frames_) {
    frame.traced_tiles.assign(std::size_t(tiles_x_ + 1) * (tiles_y_ + 1), 0u);
    frame.rects.reserve(std::size_t(tiles_x_) * tiles_y_); // a region's most
  }
  for (Source &source : sources_)
    source.tiles.assign(std::size_t(tiles_x_) * tiles_y_, kOutside);
  source_count_ = 0;
  clear();
}

void SampleStore::clear() {
  newest_ = 0;
  stored_ = 0;
  source_count_ = 0;
}

std::span<StoredSample> SampleStore::add_frame(const gpu::FrameParams &camera,
                                               const InfluenceRegion &region, std::size_t count) {
  if (count == 0 || count > samples_.size() || region.width != width_ || region.height != height_ ||
      region.pixels() == 0 || count % region.pixels() != 0 ||
      region.rects.size() > frames_[0].rects.capacity())
    return {};
  // After the newest frame's samples, or from the start where they would
  // not fit (each frame starts where the one before it ended, or at 0).
  std::size_t first = 0;
  if (stored_ > 0) {
    const Frame &newest = frames_[newest_];
    first = newest.first + newest.count;
    if (first + count > samples_.size())
      first = 0;
  }
  // The newest frame these samples overwrite goes, and every frame older
  // than it (the list runs from the newest back). Not only the oldest: after
  // a wrap to 0 the frames there are the newest, and the oldest may lie past
  // the new samples, in the end that a frame too large for it left.
  std::size_t keep = stored_;
  for (std::size_t k = 0; k < stored_; ++k) {
    const Frame &frame = frames_[(newest_ + kMostFrames - k) % kMostFrames];
    if (frame.first < first + count && first < frame.first + frame.count) {
      keep = k;
      break;
    }
  }
  stored_ = std::min(keep, kMostFrames - 1);
  newest_ = stored_ == 0 ? 0 : (newest_ + 1) % kMostFrames;
  ++stored_;
  Frame &frame = frames_[newest_];
  frame.camera = camera;
  frame.first = first;
  frame.count = count;
  frame.rects.assign(region.rects.begin(), region.rects.end());
  frame.per_pixel = std::uint32_t(count / region.pixels());
  // The region's tiles, summed: traced(...) counts them in any rectangle.
  std::fill(frame.traced_tiles.begin(), frame.traced_tiles.end(), 0u);
  const std::size_t stride = tiles_x_ + 1;
  for (const PixelRect &rect : region.rects)
    for (std::uint32_t ty = rect.y0 / CAMHEAD_TILE_Y; ty * CAMHEAD_TILE_Y < rect.y1; ++ty)
      for (std::uint32_t tx = rect.x0 / CAMHEAD_TILE_X; tx * CAMHEAD_TILE_X < rect.x1; ++tx)
        frame.traced_tiles[(ty + 1) * stride + tx + 1] = 1u;
  for (std::uint32_t ty = 1; ty <= tiles_y_; ++ty)
    for (std::uint32_t tx = 1; tx <= tiles_x_; ++tx)
      frame.traced_tiles[ty * stride + tx] += frame.traced_tiles[(ty - 1) * stride + tx] +
                                              frame.traced_tiles[ty * stride + tx - 1] -
                                              frame.traced_tiles[(ty - 1) * stride + tx - 1];
  return {samples_.data() + first, count};
}

bool SampleStore::traced(const Frame &frame, int x0, int y0, int x1, int y1) const {
  if (x0 < 0 || y0 < 0 || x1 >= int(width_) || y1 >= int(height_))
    return false; // beyond the image: never traced
  // The region is whole tiles: its pixels in the box are all traced if the
  // tiles the box meets all are.
  const std::size_t tx0 = std::size_t(x0) / CAMHEAD_TILE_X, tx1 = std::size_t(x1) / CAMHEAD_TILE_X;
  const std::size_t ty0 = std::size_t(y0) / CAMHEAD_TILE_Y, ty1 = std::size_t(y1) / CAMHEAD_TILE_Y;
  const std::size_t stride = tiles_x_ + 1;
  const std::vector<std::uint32_t> &sat = frame.traced_tiles;
  const std::uint32_t sum = sat[(ty1 + 1) * stride + tx1 + 1] - sat[ty0 * stride + tx1 + 1] -
                            sat[(ty1 + 1) * stride + tx0] + sat[ty0 * stride + tx0];
  return sum == std::uint32_t((tx1 - tx0 + 1) * (ty1 - ty0 + 1));
}

void SampleStore::begin_reprojection(const gpu::FrameParams &to, const InfluenceRegion &region,
                                     std::size_t most) {
  to_ = to;
  source_count_ = 0;
  // Through a lens model, the most it stretches a move on the ideal plane
  // out to kStretchMargin beyond the view, found once (a source that moves
  // samples further finds its own).
  constexpr double kStretchMargin = 0.05;
  const LensExtent extent = has_lens_model(to) ? lens_extent(to, kStretchMargin) : LensExtent{};
  const double stretch = extent.stretch;
  row_shift_ = float(extent.max_row_shift_px + 1.0);
  for (std::size_t k = 0; k < stored_ && source_count_ < most; ++k) {
    const Frame &frame = frames_[(newest_ + kMostFrames - k) % kMostFrames];
    if (!reprojectable(frame.camera, to))
      continue;
    Source &source = sources_[source_count_++];
    source.frame = &frame;
    // The slack: float slopes move a sample by far less than a hundredth
    // of a pixel.
    source.preimage = {
        double(frame.camera.lens.z) / double(to.lens.z),
        double(frame.camera.lens.z) * double(to.lens.x) *
                std::abs(1.0 / double(to.lens.y) - 1.0 / double(frame.camera.lens.y)) +
            0.01,
        0.5 * double(width_), 0.5 * double(height_)};
    // A row y of `frame` is seen at y' - h/2 = (y - h/2) / s + f a (w_from -
    // w_to): at most |1/s - 1| h/2 + f A_from |w_to - w_from| rows away.
    // Through a lens model, from the principal point rather than the centre,
    // and with the move on the ideal plane stretched by the lens (at most
    // lens_extent's stretch) and the image scaled as pinhole's.
    const double dw = std::abs(1.0 / double(to.lens.y) - 1.0 / double(frame.camera.lens.y));
    if (has_lens_model(to)) {
      source.preimage.move = double(to.lens.x) * dw + 1e-6;
      source.preimage.per_px = 1.1 / (double(to.lens.z) * extent.least_stretch);
      const double from_axis =
          std::max(double(to.projection.y), double(height_) - double(to.projection.y));
      const double ideal_move = double(frame.camera.lens.x) * dw;
      const double moved_stretch =
          ideal_move <= kStretchMargin ? stretch : lens_extent(to, ideal_move).stretch;
      // Out to the move beyond the view (at least A_to |dw|), where a lens
      // whose stretch grows outward (pincushion) stretches more.
      source.preimage.stretch = moved_stretch;
      source.reach = std::uint32_t(std::ceil(std::abs(1.0 / source.preimage.s - 1.0) * from_axis +
                                             moved_stretch * double(to.lens.z) * ideal_move + 2.0));
    } else {
      source.reach =
          std::uint32_t(std::ceil(std::abs(1.0 / source.preimage.s - 1.0) * 0.5 * double(height_) +
                                  double(to.lens.z) * double(frame.camera.lens.x) * dw + 2.0));
    }
    std::fill(source.tiles.begin(), source.tiles.end(), kOutside);
    for (const PixelRect &rect : region.rects)
      for (std::uint32_t ty = rect.y0 / CAMHEAD_TILE_Y; ty * CAMHEAD_TILE_Y < rect.y1; ++ty)
        for (std::uint32_t tx = rect.x0 / CAMHEAD_TILE_X; tx * CAMHEAD_TILE_X < rect.x1; ++tx) {
          const std::uint32_t x0 = tx * CAMHEAD_TILE_X, y0 = ty * CAMHEAD_TILE_Y;
          const std::uint32_t x1 = std::min(x0 + CAMHEAD_TILE_X, width_);
          const std::uint32_t y1 = std::min(y0 + CAMHEAD_TILE_Y, height_);
          source.tiles[std::size_t(ty) * tiles_x_ + tx] =
              covers(frame, source.preimage, x0, y0, x1, y1) ? kCovered : kEdge;
        }
  }
}

bool SampleStore::covers_through_lens(const Frame &frame, const Preimage &p, std::uint32_t x0,
                                      std::uint32_t y0, std::uint32_t x1, std::uint32_t y1) const {
  const glm::vec2 centre = ideal_to_pixel(
      frame.camera, pixel_to_ideal(to_, 0.5f * glm::vec2(float(x0 + x1), float(y0 + y1))));
  const double half_diagonal = 0.5 * std::hypot(double(x1 - x0), double(y1 - y0));
  constexpr double kMarginPx = 0.05; // the rounding of the floats
  const double reach =
      (half_diagonal * p.per_px + p.move) * double(frame.camera.lens.z) * p.stretch + kMarginPx;
  if (!std::isfinite(double(centre.x) + double(centre.y) + reach))
    return false;
  return traced(
      frame, int(std::floor(double(centre.x) - reach)), int(std::floor(double(centre.y) - reach)),
      int(std::ceil(double(centre.x) + reach)) - 1, int(std::ceil(double(centre.y) + reach)) - 1);
}

} // namespace camhead::renderer::cpu
