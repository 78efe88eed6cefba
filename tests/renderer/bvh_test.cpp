// The BVH is checked as a data structure (coverage, nesting, stats) and as an
// acceleration structure: a small closest-hit traversal written here must
// find exactly what brute force finds. The real traversal is the kernel's;
// this one is only an oracle for the structure.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/bvh.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

using gpu::Primitive;
constexpr float kInf = std::numeric_limits<float>::infinity();
const std::filesystem::path kBunny = "/usr/share/glmark2/models/bunny.obj";

std::uint32_t w_bits(float w) {
  return glm::floatBitsToUint(w);
}

Primitive triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, std::uint32_t id = 0) {
  return {gpu::vec4(a, glm::uintBitsToFloat(id)), gpu::vec4(b - a, 0), gpu::vec4(c - a, 0)};
}

Primitive sphere(glm::vec3 c, float r, std::uint32_t id = 0) {
  return {gpu::vec4(c, glm::uintBitsToFloat(id | PRIM_SPHERE << 24)), gpu::vec4(r, 0, 0, 0),
          gpu::vec4(0)};
}

bool is_sphere(const Primitive &p) {
  return (w_bits(p.p0.w) >> 24) == PRIM_SPHERE;
}

struct Box {
  glm::vec3 lo{kInf}, hi{-kInf};
  void grow(const Box &b) { lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi); }
  [[nodiscard]] glm::vec3 centre() const { return 0.5f * (lo + hi); }
  [[nodiscard]] bool contains(const Box &b) const {
    return glm::all(glm::lessThanEqual(lo, b.lo)) && glm::all(glm::lessThanEqual(b.hi, hi));
  }
};

Box prim_bounds(const Primitive &p) {
  const glm::vec3 v0(p.p0);
  if (is_sphere(p))
    return {v0 - glm::vec3(p.p1.x), v0 + glm::vec3(p.p1.x)};
  const glm::vec3 v1 = v0 + glm::vec3(p.p1), v2 = v0 + glm::vec3(p.p2);
  return {glm::min(v0, glm::min(v1, v2)), glm::max(v0, glm::max(v1, v2))};
}

Box node_bounds(const gpu::BvhNode &n) {
  return {glm::vec3(n.bmin), glm::vec3(n.bmax)};
}

// The bunny as bare OBJ "v" and "f" records (the mesh loader is tested on its own).
std::vector<Primitive> load_bunny() {
  std::ifstream in(kBunny);
  std::vector<glm::vec3> v;
  std::vector<Primitive> tris;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      glm::vec3 p;
      s >> p.x >> p.y >> p.z;
      v.push_back(p);
    } else if (tag == "f") { // the bunny's faces are plain "f a b c" triangles
      int a = 0, b = 0, c = 0;
      s >> a >> b >> c;
      tris.push_back(triangle(v.at(a - 1), v.at(b - 1), v.at(c - 1)));
    }
  }
  return tris;
}

// ---------------------------------------------------------------- ray oracle
struct Ray {
  glm::vec3 o, d;
};

float intersect(const Primitive &p, const Ray &r) {
  const glm::vec3 v0(p.p0);
  if (is_sphere(p)) {
    const glm::vec3 oc = r.o - v0;
    const float b = glm::dot(oc, r.d), c = glm::dot(oc, oc) - p.p1.x * p.p1.x;
    const float disc = b * b - c;
    if (disc < 0)
      return kInf;
    const float s = std::sqrt(disc);
    const float t = -b - s > 0 ? -b - s : -b + s;
    return t > 0 ? t : kInf;
  }
  const glm::vec3 e1(p.p1), e2(p.p2);
  const glm::vec3 pv = glm::cross(r.d, e2);
  const float det = glm::dot(e1, pv);
  if (det == 0)
    return kInf;
  const float inv = 1 / det;
  const glm::vec3 tv = r.o - v0;
  const float u = glm::dot(tv, pv) * inv;
  if (u < 0 || u > 1)
    return kInf;
  const glm::vec3 qv = glm::cross(tv, e1);
  const float v = glm::dot(r.d, qv) * inv;
  if (v < 0 || u + v > 1)
    return kInf;
  const float t = glm::dot(e2, qv) * inv;
  return t > 0 ? t : kInf;
}

// Rays have a finite extent, as in the kernels; the empty BVH relies on it.
struct Hit {
  float t = std::numeric_limits<float>::max();
  const Primitive *prim = nullptr;
};

Hit brute_force(const std::vector<Primitive> &prims, const Ray &r) {
  Hit h;
  for (const Primitive &p : prims)
    if (const float t = intersect(p, r); t < h.t)
      h = {t, &p};
  return h;
}

Hit traverse(const Bvh &bvh, const Ray &r) {
  const glm::vec3 inv = 1.0f / r.d;
  Hit h;
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const gpu::BvhNode &n = bvh.nodes.at(stack.back());
    stack.pop_back();
    const glm::vec3 t0 = (glm::vec3(n.bmin) - r.o) * inv, t1 = (glm::vec3(n.bmax) - r.o) * inv;
    const glm::vec3 tn = glm::min(t0, t1), tf = glm::max(t0, t1);
    const float t_near = std::max({tn.x, tn.y, tn.z}), t_far = std::min({tf.x, tf.y, tf.z});
    if (!(t_near <= t_far && t_far >= 0 && t_near <= h.t))
      continue;
    const std::uint32_t count = w_bits(n.bmax.w), first = w_bits(n.bmin.w);
    if (count == 0) {
      stack.insert(stack.end(), {first, first + 1});
      continue;
    }
    for (std::uint32_t k = first; k < first + count; ++k)
      if (const float t = intersect(bvh.primitives.at(k), r); t < h.t)
        h = {t, &bvh.primitives[k]};
  }
  return h;
}

// Returns the number of rays on which the BVH disagrees with brute force. A
// tie at equal t may pick another primitive, so the BVH's pick is re-tested.
int count_mismatches(const std::vector<Primitive> &input, const Bvh &bvh,
                     const std::vector<Ray> &rays, int *hits) {
  int bad = 0;
  for (const Ray &r : rays) {
    const Hit want = brute_force(input, r), got = traverse(bvh, r);
    *hits += want.prim != nullptr;
    if (want.t != got.t || (got.prim && intersect(*got.prim, r) != want.t))
      ++bad;
  }
  return bad;
}

// ---------------------------------------------------------------- structure
float area(const Box &b) {
  const glm::vec3 d = glm::max(b.hi - b.lo, glm::vec3(0));
  return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

// Walks the tree; checks coverage, nesting, bounds and the stats.
void check_structure(const std::vector<Primitive> &input, const Bvh &bvh) {
  ASSERT_FALSE(bvh.nodes.empty());
  ASSERT_EQ(bvh.primitives.size(), input.size());
  auto bytes = [](const std::vector<Primitive> &v) {
    std::vector<std::string> out;
    for (const Primitive &p : v)
      out.emplace_back(reinterpret_cast<const char *>(&p), sizeof p);
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_EQ(bytes(input), bytes(bvh.primitives)) << "leaf order is not a permutation";

  Box all;
  for (const Primitive &p : input)
    all.grow(prim_bounds(p));
  std::vector<int> node_seen(bvh.nodes.size(), 0), prim_seen(input.size(), 0);
  BvhStats st;
  double cost = 0;
  const float root_area = area(node_bounds(bvh.nodes[0]));
  std::vector<std::pair<std::uint32_t, int>> stack{{0, 0}}; // node, depth
  while (!stack.empty()) {
    const auto [i, depth] = stack.back();
    stack.pop_back();
    ASSERT_LT(i, bvh.nodes.size());
    ASSERT_EQ(node_seen[i]++, 0) << "node " << i << " reached twice";
    const gpu::BvhNode &n = bvh.nodes[i];
    st.max_depth = std::max(st.max_depth, depth);
    const std::uint32_t count = w_bits(n.bmax.w), first = w_bits(n.bmin.w);
    if (count == 0) {
      ASSERT_GT(first, i) << "children must follow their parent";
      ASSERT_LT(first + 1, bvh.nodes.size());
      for (std::uint32_t c : {first, first + 1}) {
        EXPECT_TRUE(node_bounds(n).contains(node_bounds(bvh.nodes[c])))
            << "child " << c << " leaves parent " << i;
        stack.push_back({c, depth + 1});
      }
      cost += area(node_bounds(n));
      continue;
    }
    ++st.leaf_count;
    st.max_leaf_size = std::max(st.max_leaf_size, int(count));
    cost += double(area(node_bounds(n))) * count;
    ASSERT_LE(std::uint64_t(first) + count, input.size());
    for (std::uint32_t k = first; k < first + count; ++k) {
      ++prim_seen[k];
      EXPECT_TRUE(node_bounds(n).contains(prim_bounds(bvh.primitives[k])))
          << "primitive " << k << " outside leaf " << i;
    }
  }
  EXPECT_TRUE(std::all_of(node_seen.begin(), node_seen.end(), [](int s) { return s == 1; }))
      << "unreachable nodes";
  EXPECT_TRUE(std::all_of(prim_seen.begin(), prim_seen.end(), [](int s) { return s == 1; }))
      << "a primitive is in no leaf or in two";
  EXPECT_EQ(bvh.stats.node_count, int(bvh.nodes.size()));
  EXPECT_EQ(bvh.stats.leaf_count, st.leaf_count);
  EXPECT_EQ(bvh.stats.max_depth, st.max_depth);
  EXPECT_EQ(bvh.stats.max_leaf_size, st.max_leaf_size);
  EXPECT_LE(bvh.stats.max_leaf_size, 8);
  if (area(all) > 0) { // node bounds carry a few ulps of padding
    EXPECT_NEAR(bvh.stats.sah_cost, cost / root_area, 1e-4 * cost / root_area);
  } else { // no area to measure probabilities with: every primitive is tested
    EXPECT_EQ(bvh.stats.sah_cost, float(input.size()));
  }
}

// SAH cost of an object-median BVH (longest centroid axis), the baseline.
double median_cost(std::vector<Primitive> &prims, std::size_t b, std::size_t e, int max_leaf) {
  Box box, cbox;
  for (std::size_t i = b; i < e; ++i) {
    const Box pb = prim_bounds(prims[i]);
    box.grow(pb);
    cbox.grow({pb.centre(), pb.centre()});
  }
  if (int(e - b) <= max_leaf)
    return double(area(box)) * double(e - b);
  const glm::vec3 ext = cbox.hi - cbox.lo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  const std::size_t mid = (b + e) / 2;
  std::nth_element(prims.begin() + b, prims.begin() + mid, prims.begin() + e,
                   [axis](const Primitive &l, const Primitive &r) {
                     return prim_bounds(l).centre()[axis] < prim_bounds(r).centre()[axis];
                   });
  return area(box) + median_cost(prims, b, mid, max_leaf) + median_cost(prims, mid, e, max_leaf);
}

// Rays from in and around the scene's box toward random points of it, half
// of them aimed at primitive centres so that most hit something.
std::vector<Ray> make_rays(const std::vector<Primitive> &prims, int n, std::uint32_t seed) {
  Box box;
  for (const Primitive &p : prims)
    box.grow(prim_bounds(p));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  auto in_box = [&](float grow) {
    const glm::vec3 c = box.centre(), h = (box.hi - box.lo) * (0.5f * grow);
    return c + h * glm::vec3(2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1);
  };
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 o = in_box(3.0f);
    glm::vec3 target = in_box(1.0f);
    if (i % 2 == 0)
      target = prim_bounds(prims[rng() % prims.size()]).centre();
    rays.push_back({o, glm::normalize(target - o)});
  }
  return rays;
}

std::vector<Primitive> random_mix(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  auto v = [&] { return glm::vec3(u(rng), u(rng), u(rng)); };
  std::vector<Primitive> prims;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 c = 5.0f * v();
    const float size = 0.02f + 0.5f * std::abs(u(rng)) * std::abs(u(rng));
    prims.push_back(i % 3 == 0 ? sphere(c, size, i)
                               : triangle(c + size * v(), c + size * v(), c + size * v(), i));
  }
  return prims;
}

// ---------------------------------------------------------------- tests
TEST(Bvh, EmptyInputIsOneNodeNoRayEnters) {
  const Bvh bvh = build_bvh({});
  ASSERT_EQ(bvh.nodes.size(), 1u);
  EXPECT_TRUE(bvh.primitives.empty());
  const std::vector<Ray> rays = {{{0, 0, 0}, {1, 0, 0}},
                                 {{0, 0, 0}, {-1, 0, 0}},
                                 {{1, 2, 3}, {0, 0, -1}},
                                 {{5, 5, 5}, glm::normalize(glm::vec3(1))},
                                 {{-9, 0, 0}, {0.6f, 0.8f, 0}}};
  for (const Ray &r : rays)
    EXPECT_EQ(traverse(bvh, r).prim, nullptr); // the root box is never entered
}

TEST(Bvh, SinglePrimitiveIsOneLeaf) {
  const std::vector<Primitive> in = {triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0})};
  const Bvh bvh = build_bvh(in);
  check_structure(in, bvh);
  EXPECT_EQ(bvh.nodes.size(), 1u);
  EXPECT_EQ(traverse(bvh, {{0.2f, 0.2f, 1}, {0, 0, -1}}).t, 1.0f);
}

TEST(Bvh, CoincidentAndDegeneratePrimitives) {
  std::vector<Primitive> same(1000, triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  std::vector<Primitive> at_point(300, triangle({2, 2, 2}, {2, 2, 2}, {2, 2, 2}));
  std::vector<Primitive> zero_area;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-3, 3);
  for (int i = 0; i < 500; ++i) {
    const glm::vec3 a(u(rng), u(rng), u(rng)), d(u(rng), u(rng), u(rng));
    zero_area.push_back(i % 2 ? triangle(a, a, a) : triangle(a, a + d, a + 2.0f * d));
  }
  for (const auto *in : {&same, &at_point, &zero_area}) {
    const Bvh bvh = build_bvh(*in);
    check_structure(*in, bvh);
    EXPECT_LE(bvh.stats.max_depth, 16);
  }
}

TEST(Bvh, DepthStaysBoundedOnExponentialSpacing) {
  std::vector<Primitive> in;
  for (int i = 0; i < 2000; ++i)
    in.push_back(sphere({std::pow(1.03f, float(i)), 0, 0}, 0.01f));
  const Bvh bvh = build_bvh(in);
  check_structure(in, bvh);
  EXPECT_LE(bvh.stats.max_depth, 64); // the kernels' traversal stack
}

TEST(Bvh, RandomSpheresAndTrianglesMatchBruteForce) {
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    const std::vector<Primitive> in = random_mix(1500, seed);
    const Bvh bvh = build_bvh(in);
    check_structure(in, bvh);
    int hits = 0;
    EXPECT_EQ(count_mismatches(in, bvh, make_rays(in, 3000, seed), &hits), 0);
    EXPECT_GT(hits, 1500);
  }
}

TEST(Bvh, BunnyBuildsFastWithLowSahCostAndMatchesBruteForce) {
  if (!std::filesystem::exists(kBunny))
    GTEST_SKIP() << kBunny << " not installed (glmark2-data)";
  const std::vector<Primitive> in = load_bunny();
  ASSERT_GT(in.size(), 60000u);
  const auto t0 = std::chrono::steady_clock::now();
  const Bvh bvh = build_bvh(in);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const float root_area = area(node_bounds(bvh.nodes[0]));
  std::vector<Primitive> scratch = in;
  const double median4 = median_cost(scratch, 0, scratch.size(), 4) / root_area;
  const double median8 = median_cost(scratch, 0, scratch.size(), 8) / root_area;
  std::cout << "bunny: " << in.size() << " triangles, build " << seconds * 1e3 << " ms, "
            << bvh.stats.node_count << " nodes, " << bvh.stats.leaf_count << " leaves, depth "
            << bvh.stats.max_depth << ", max leaf " << bvh.stats.max_leaf_size << ", SAH cost "
            << bvh.stats.sah_cost << " (object median: " << median4 << " with leaves <= 4, "
            << median8 << " with <= 8)\n";
  EXPECT_LT(seconds, 5.0); // a gross-regression guard: ~70 ms here, ~1 s under ASan
  check_structure(in, bvh);
  EXPECT_LT(bvh.stats.sah_cost, 0.9 * std::min(median4, median8));
  int hits = 0;
  EXPECT_EQ(count_mismatches(in, bvh, make_rays(in, 2000, 11), &hits), 0);
  EXPECT_GT(hits, 1000);
}

} // namespace
} // namespace camhead::renderer
