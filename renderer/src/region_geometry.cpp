// See region_geometry.h.
#include "region_geometry.h"

namespace camhead::renderer::region_geometry {

// Andrew's monotone chain: the corners of the hull of `points` (sorted in
// place) in order, into `hull` (collinear points dropped); fewer than three
// points come back as they are. `hull` needs room for 2 points.size().
void convex_hull(std::span<Point> points, std::vector<Point> &hull) {
  std::sort(points.begin(), points.end(),
            [](const Point &a, const Point &b) { return a.u != b.u ? a.u < b.u : a.v < b.v; });
  hull.clear();
  if (points.size() < 3) {
    hull.insert(hull.end(), points.begin(), points.end());
    return;
  }
  const auto turn = [](const Point &o, const Point &a, const Point &b) {
    return (a.u - o.u) * (b.v - o.v) - (a.v - o.v) * (b.u - o.u);
  };
  hull.resize(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) { // lower chain
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], points[i]) <= 0.0)
      --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) { // upper chain
    while (k >= lower && turn(hull[k - 2], hull[k - 1], points[i]) <= 0.0)
      --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1); // the last point is the first
}

void FrameProjector::finish(InfluenceRegion &region) {
  region.width = width_;
  region.height = height_;
  region.rects.clear();
  const auto pixel_rect = [&](std::uint32_t tx0, std::uint32_t tx1, std::uint32_t ty0,
                              std::uint32_t ty1) {
    return PixelRect{tx0 * CAMHEAD_TILE_X, ty0 * CAMHEAD_TILE_Y,
                     std::min(tx1 * CAMHEAD_TILE_X, width_),
                     std::min(ty1 * CAMHEAD_TILE_Y, height_)};
  };
  // Runs of tiles, a row at a time; a run that repeats the one above
  // extends its rectangle.
  open_.clear();
  for (std::uint32_t ty = 0; ty <= tiles_y_; ++ty) {
    next_.clear();
    std::uint32_t tx = 0;
    while (ty < tiles_y_ && tx < tiles_x_) {
      if (!marked_[std::size_t(ty) * tiles_x_ + tx]) {
        ++tx;
        continue;
      }
      const std::uint32_t start = tx;
      while (tx < tiles_x_ && marked_[std::size_t(ty) * tiles_x_ + tx])
        ++tx;
      const auto above = std::find_if(open_.begin(), open_.end(),
                                      [&](const Open &o) { return o.tx0 == start && o.tx1 == tx; });
      next_.push_back({start, tx, above != open_.end() ? above->ty0 : ty});
      if (above != open_.end())
        open_.erase(above);
    }
    for (const Open &o : open_) // not continued in this row
      region.rects.push_back(pixel_rect(o.tx0, o.tx1, o.ty0, ty));
    std::swap(open_, next_);
  }
  std::sort(region.rects.begin(), region.rects.end(), [](const PixelRect &a, const PixelRect &b) {
    return a.y0 != b.y0 ? a.y0 < b.y0 : a.x0 < b.x0;
  });
}

} // namespace camhead::renderer::region_geometry
