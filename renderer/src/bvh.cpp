// Binned SAH BVH builder (Wald 2007, "On fast construction of SAH-based
// bounding volume hierarchies"), written straight into the flat layout of
// layout.h: children of a node are allocated as a pair, so the right child is
// always left + 1 and the kernels need no second index.
#include "camhead/renderer/bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace camhead::renderer {
namespace {

// Bins per axis. Small nodes get one bin per primitive (at least two): most
// of 32 bins would stay empty there, and clearing and sweeping them was most
// of the build time (the bunny's SAH cost is unchanged).
constexpr int kMaxBins = 32;
constexpr std::uint32_t kMaxLeafSize = 8;
// One node visit costs about one primitive test in the kernels; the SAH and
// the reported cost both use this ratio.
constexpr float kTraversalCost = 1.0f;
// Below this depth the SAH decides; deeper, splits fall back to the object
// median, which bounds the depth (and so the kernels' fixed traversal stack)
// even for inputs on which the SAH peels off one primitive at a time.
constexpr int kMaxSahDepth = 40;
// The kernels rebuild v1 = v0 + p1 and round in their slab tests; a few ulps
// of slack keep hits on a node's faces from slipping between node and
// primitive. Padding by a fraction of |x| is monotonic, so nesting survives.
constexpr float kPadding = 4.0f * std::numeric_limits<float>::epsilon();

constexpr float kInf = std::numeric_limits<float>::infinity();

struct Aabb {
  glm::vec3 lo{kInf};
  glm::vec3 hi{-kInf};

  void grow(const glm::vec3 &p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Aabb &b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  [[nodiscard]] float area() const {
    const glm::vec3 d = hi - lo;
    if (d.x < 0.0f || d.y < 0.0f || d.z < 0.0f)
      return 0.0f;
    return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

Aabb primitive_bounds(const gpu::Primitive &p) {
  Aabb b;
  const glm::vec3 v0(p.p0);
  if ((glm::floatBitsToUint(p.p0.w) >> 24) == PRIM_SPHERE) {
    const float r = std::abs(p.p1.x);
    b.grow(v0 - glm::vec3(r));
    b.grow(v0 + glm::vec3(r));
  } else {
    b.grow(v0);
    b.grow(v0 + glm::vec3(p.p1));
    b.grow(v0 + glm::vec3(p.p2));
  }
  return b;
}

// Maps centroids to bins along one axis. Written so that the binning pass and
// the partition pass agree exactly, and NaN lands in bin 0 instead of UB.
struct Binner {
  float lo = 0.0f;
  float scale = 0.0f; // 0: the axis cannot be split
  int count = 0;

  Binner(float min_c, float max_c, int bins) : lo(min_c), count(bins) {
    const float extent = max_c - min_c;
    const float s = float(bins) / extent;
    if (extent > 0.0f && std::isfinite(s))
      scale = s;
  }
  [[nodiscard]] int bin(float c) const {
    const float f = std::max(0.0f, (c - lo) * scale);
    return int(std::min(f, float(count - 1)));
  }
};

struct Split {
  int axis = -1; // -1: no SAH split exists
  int bin = 0;   // the left side takes bins [0, bin]
  float cost = kInf;
};

// Bounds and centroid travel with the index so that the passes over a node
// read memory in order.
struct PrimRef {
  Aabb box;
  glm::vec3 centroid;
  std::uint32_t index;
};

struct Task {
  std::uint32_t node;
  std::uint32_t begin;
  std::uint32_t end;
  int depth;
};

class Builder {
public:
  explicit Builder(const std::vector<gpu::Primitive> &prims) : prims_(prims) {
    refs_.reserve(prims.size());
    for (std::uint32_t i = 0; i < prims.size(); ++i) {
      const Aabb b = primitive_bounds(prims[i]);
      refs_.push_back(PrimRef{b, 0.5f * (b.lo + b.hi), i});
    }
  }

  void build(Bvh &out);

private:
  // The SAH in unnormalised form (costs times the parent's area), so that
  // boxes of zero area need no division.
  [[nodiscard]] Split find_split(std::uint32_t begin, std::uint32_t end,
                                 const std::array<Binner, 3> &binners) const;
  [[nodiscard]] std::uint32_t median_split(std::uint32_t begin, std::uint32_t end,
                                           const Aabb &cbox);

  const std::vector<gpu::Primitive> &prims_;
  std::vector<PrimRef> refs_;
  std::vector<gpu::BvhNode> nodes_;
};

Split Builder::find_split(std::uint32_t begin, std::uint32_t end,
                          const std::array<Binner, 3> &binners) const {
  // Left uninitialised but for the bins in use: clearing all of them was a
  // large share of the build time, most nodes being small.
  struct Bin {
    glm::vec3 lo, hi;
    std::uint32_t count;
  };
  std::array<std::array<Bin, kMaxBins>, 3> bins;
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < binners[a].count; ++i)
      bins[a][i] = Bin{glm::vec3(kInf), glm::vec3(-kInf), 0};
  for (std::uint32_t i = begin; i < end; ++i) {
    const PrimRef &r = refs_[i];
    for (int a = 0; a < 3; ++a) {
      if (binners[a].scale == 0.0f)
        continue;
      Bin &b = bins[a][binners[a].bin(r.centroid[a])];
      b.lo = glm::min(b.lo, r.box.lo);
      b.hi = glm::max(b.hi, r.box.hi);
      ++b.count;
    }
  }

  Split best;
  for (int a = 0; a < 3; ++a) {
    if (binners[a].scale == 0.0f)
      continue;
    // Sweep from the right storing the suffix costs, then from the left.
    const int nb = binners[a].count;
    std::array<float, kMaxBins> right_cost;
    Aabb acc;
    std::uint32_t n = 0;
    for (int i = nb - 1; i > 0; --i) {
      acc.grow(Aabb{bins[a][i].lo, bins[a][i].hi});
      n += bins[a][i].count;
      right_cost[i] = acc.area() * float(n);
    }
    acc = Aabb{};
    n = 0;
    const std::uint32_t total = end - begin;
    for (int i = 0; i < nb - 1; ++i) {
      acc.grow(Aabb{bins[a][i].lo, bins[a][i].hi});
      n += bins[a][i].count;
      if (n == 0 || n == total)
        continue;
      const float cost = acc.area() * float(n) + right_cost[i + 1];
      if (cost < best.cost)
        best = Split{a, i, cost};
    }
  }
  return best;
}

std::uint32_t Builder::median_split(std::uint32_t begin, std::uint32_t end, const Aabb &cbox) {
  const glm::vec3 extent = cbox.hi - cbox.lo;
  const int axis =
      extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const std::uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(
      refs_.begin() + begin, refs_.begin() + mid, refs_.begin() + end,
      [axis](const PrimRef &l, const PrimRef &r) { return l.centroid[axis] < r.centroid[axis]; });
  return mid;
}

gpu::BvhNode make_node(const Aabb &box, std::uint32_t w_min, std::uint32_t w_max) {
  const glm::vec3 lo = box.lo - glm::abs(box.lo) * kPadding;
  const glm::vec3 hi = box.hi + glm::abs(box.hi) * kPadding;
  return gpu::BvhNode{gpu::vec4(lo, glm::uintBitsToFloat(w_min)),
                      gpu::vec4(hi, glm::uintBitsToFloat(w_max))};
}

void Builder::build(Bvh &out) {
  BvhStats &st = out.stats;
  const auto count = std::uint32_t(refs_.size());
  if (count == 0) {
    // The layout has no empty leaf (count 0 means interior), so the root must
    // never be entered. Bounds at +inf on every axis put each slab interval
    // at +inf or -inf: a ray of finite extent misses (an inverted box would
    // not do: the slab test's per-axis min/max undoes the inversion). Kernels
    // should still skip traversal when the primitive count is 0.
    out.nodes.push_back(gpu::BvhNode{gpu::vec4(kInf, kInf, kInf, glm::uintBitsToFloat(0u)),
                                     gpu::vec4(kInf, kInf, kInf, glm::uintBitsToFloat(0u))});
    st = BvhStats{1, 1, 0, 0, 0.0f};
    return;
  }

  nodes_.reserve(2 * std::size_t(count));
  nodes_.emplace_back();
  std::vector<Task> stack{{0, 0, count, 0}};
  double interior_area = 0.0, leaf_area = 0.0, root_area = 0.0;
  while (!stack.empty()) {
    const Task t = stack.back();
    stack.pop_back();
    Aabb box, cbox;
    for (std::uint32_t i = t.begin; i < t.end; ++i) {
      box.grow(refs_[i].box);
      cbox.grow(refs_[i].centroid);
    }
    if (t.node == 0)
      root_area = box.area();
    st.max_depth = std::max(st.max_depth, t.depth);

    const std::uint32_t n = t.end - t.begin;
    Split split;
    const int nb = int(std::clamp<std::uint32_t>(n, 2, kMaxBins));
    const std::array<Binner, 3> binners{Binner(cbox.lo.x, cbox.hi.x, nb),
                                        Binner(cbox.lo.y, cbox.hi.y, nb),
                                        Binner(cbox.lo.z, cbox.hi.z, nb)};
    if (n > 1)
      split = find_split(t.begin, t.end, binners);
    const float leaf_cost = box.area() * float(n);
    const float split_cost = kTraversalCost * box.area() + split.cost;
    if (n == 1 || (n <= kMaxLeafSize && !(split_cost < leaf_cost))) {
      nodes_[t.node] = make_node(box, t.begin, n);
      ++st.leaf_count;
      st.max_leaf_size = std::max(st.max_leaf_size, int(n));
      leaf_area += double(box.area()) * n;
      continue;
    }

    std::uint32_t mid = 0;
    if (split.axis < 0 || t.depth >= kMaxSahDepth) {
      mid = median_split(t.begin, t.end, cbox);
    } else {
      const Binner &b = binners[split.axis];
      const int axis = split.axis, last = split.bin;
      const auto it =
          std::partition(refs_.begin() + t.begin, refs_.begin() + t.end,
                         [&](const PrimRef &r) { return b.bin(r.centroid[axis]) <= last; });
      mid = std::uint32_t(it - refs_.begin());
    }
    const auto left = std::uint32_t(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[t.node] = make_node(box, left, 0u);
    interior_area += box.area();
    // Right first so that the left subtree is built (and laid out) first.
    stack.push_back({left + 1, mid, t.end, t.depth + 1});
    stack.push_back({left, t.begin, mid, t.depth + 1});
  }

  st.node_count = int(nodes_.size());
  // A root of zero area (all primitives at one point) has no SAH probability
  // measure; every ray that reaches it tests every primitive.
  st.sah_cost = root_area > 0.0 ? float((kTraversalCost * interior_area + leaf_area) / root_area)
                                : float(count);
  out.nodes = std::move(nodes_);
  out.primitives.reserve(count);
  for (const PrimRef &r : refs_)
    out.primitives.push_back(prims_[r.index]);
}

} // namespace

Bvh build_bvh(std::vector<gpu::Primitive> primitives) {
  Bvh bvh;
  Builder(primitives).build(bvh);
  return bvh;
}

} // namespace camhead::renderer
