// Bounding volume hierarchy over primitives, built on the CPU with the
// surface-area heuristic (binned), flattened for traversal in the kernels.
#pragma once

#include <vector>

#include "camhead/renderer/gpu_layout.h"

namespace camhead::renderer {

struct BvhStats {
  int node_count = 0;
  int leaf_count = 0;
  int max_depth = 0;
  int max_leaf_size = 0;
  float sah_cost = 0.0f; // expected cost relative to one primitive test
};

struct Bvh {
  std::vector<gpu::BvhNode> nodes;        // nodes[0] is the root
  std::vector<gpu::Primitive> primitives; // reordered to leaf order
  BvhStats stats;
};

// Builds a BVH over `primitives` (any mix of triangles and spheres). An empty
// input gives a single empty leaf whose bounds no ray hits.
[[nodiscard]] Bvh build_bvh(std::vector<gpu::Primitive> primitives);

} // namespace camhead::renderer
