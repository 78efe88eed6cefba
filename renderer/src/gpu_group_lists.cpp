// See gpu_group_lists.h.
#include "gpu_group_lists.h"

#include <algorithm>

namespace camhead::renderer {

std::uint32_t tiles_of(std::uint32_t width, std::uint32_t height) {
  return ((width + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X) *
         ((height + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y);
}

std::uint32_t group_place(std::uint32_t x, std::uint32_t y) {
  return y << 16 | x;
}

void tile_places(const InfluenceRegion &region, std::vector<std::uint32_t> &places) {
  for (const PixelRect &rect : region.rects)
    for (std::uint32_t ty = rect.y0 / CAMHEAD_TILE_Y;
         ty < (rect.y1 + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y; ++ty)
      for (std::uint32_t tx = rect.x0 / CAMHEAD_TILE_X;
           tx < (rect.x1 + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X; ++tx)
        places.push_back(group_place(tx, ty));
}

void video_group_places(const InfluenceRegion &region, glm::uvec2 groups,
                        std::vector<glm::uvec2> &spans, std::vector<std::uint32_t> &places) {
  for (std::uint32_t gy = 0; gy < groups.y; ++gy) {
    spans.clear();
    const std::uint32_t y0 = gy * VIDEO_GROUP_Y;
    for (const PixelRect &rect : region.rects)
      if (rect.y0 < y0 + VIDEO_GROUP_Y && rect.y1 > y0)
        spans.emplace_back(rect.x0 / VIDEO_GROUP_X, (rect.x1 + VIDEO_GROUP_X - 1) / VIDEO_GROUP_X);
    std::sort(spans.begin(), spans.end(), [](glm::uvec2 a, glm::uvec2 b) { return a.x < b.x; });
    std::uint32_t next = 0; // the row's first group not yet listed
    for (const glm::uvec2 span : spans) {
      for (std::uint32_t gx = std::max(span.x, next); gx < span.y; ++gx)
        places.push_back(group_place(gx, gy));
      next = std::max(next, span.y);
    }
  }
}

} // namespace camhead::renderer
