// The influence region (influence_region.h), in three steps:
//
// 1. World space. The points where a virtual object can change what a camera
//    ray brings back, as convex polyhedra:
//    - each virtual object's bounds (its box aligned with the world, cut to
//      its box along its own axes, which a rotated box or plane fills): a
//      ray that meets it;
//    - each real mirror's or glass's bounds: a ray that meets one may go on
//      to a virtual object or its shadow (however many bounces follow);
//    - for each light, virtual object and real diffuse object: the points of
//      that real object whose shadow ray to the light can meet the virtual
//      object. Those points are v + t (v - l) with v in the object's box B,
//      l on the light (a point, the rectangle of an area light, or a sun's
//      direction at infinity) and t >= 0, a subset of B + cone(D) with D
//      the differences of their corners; that set is cut out of the real
//      object's bounds by the supporting planes of B + cone(D) (normals
//      across pairs of generators, each kept only if the whole set lies
//      behind it), for each of the caster's two boxes.
//      A sphere counts as its box with edges and corners cut off, and its
//      shadow from a point light or a sun as the planes tangent to its
//      round shadow cone or cylinder.
//    Everything is grown by a margin above the kernel's ray offsets and
//    float rounding.
// 2. The thin lens. A point at depth z is seen by the pixels within
//    f A |1/F - 1/z| pixels of its pinhole projection (aperture radius A,
//    focal-plane depth F, focal length f in pixels); for a given aperture
//    point a lens ray is a perspective projection, so a polyhedron's image
//    lies in the convex hull of its vertices' images, each grown by its own
//    blur (an octagon around the blur circle). Points behind the lens are
//    cut off; a piece within a millimetre of it, where the projection
//    diverges, takes the whole frame if a camera ray can get there.
// 3. Pixels and tiles. Each hull, widened by the pixel filter and a pixel of
//    margin, marks the tiles it touches, a row of tiles at a time; runs of
//    tiles are merged into rectangles.
//
// Step 1 depends on the scene alone: InfluenceRegionBuilder makes it once,
// and steps 2 and 3 run per frame in storage it keeps (FrameProjector).
#include "camhead/renderer/influence_region.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace camhead::renderer {
namespace {

using glm::dvec3;

// n . x <= h
struct Halfspace {
  dvec3 n;
  double h;
};

// A closed convex polyhedron as its faces (convex polygons, vertices in
// order), cut down one half-space at a time. Its faces lie end to end in
// one array, so that a polyhedron cut into another's storage allocates
// nothing once that storage has grown to fit.
class ConvexPolyhedron {
public:
  static ConvexPolyhedron box(const dvec3 &lo, const dvec3 &hi) {
    std::array<dvec3, 8> c;
    for (int i = 0; i < 8; ++i)
      c[i] = dvec3(i & 4 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 1 ? hi.z : lo.z);
    constexpr int kFaces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                  {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    ConvexPolyhedron p;
    for (const auto &f : kFaces) {
      for (const int corner : f)
        p.vertices_.push_back(c[std::size_t(corner)]);
      p.face_ends_.push_back(p.vertices_.size());
    }
    return p;
  }

  [[nodiscard]] bool empty() const { return face_ends_.empty(); }
  [[nodiscard]] std::size_t vertex_storage() const { return vertices_.size(); }
  [[nodiscard]] std::size_t faces() const { return face_ends_.size(); }

  // Room for `vertices` and `faces` without growing.
  void reserve(std::size_t vertices, std::size_t faces) {
    vertices_.reserve(vertices);
    face_ends_.reserve(faces);
  }

  // The part with n . x <= h, closed by a new face on the plane, into `out`
  // (its storage reused); `cap` is scratch. A face loses its outside
  // vertices and gains at most two, and the new face takes two points of
  // each face cut (an edge's point twice), so `out` needs at most
  // vertex_storage() + 4 faces() vertices and faces() + 1 faces.
  void clip_into(const Halfspace &plane, ConvexPolyhedron &out, std::vector<dvec3> &cap) const {
    out.vertices_.clear();
    out.face_ends_.clear();
    cap.clear();
    std::size_t begin = 0;
    for (const std::size_t end : face_ends_) {
      const std::size_t kept_from = out.vertices_.size();
      for (std::size_t i = begin; i < end; ++i) {
        const dvec3 &a = vertices_[i];
        const dvec3 &b = vertices_[i + 1 < end ? i + 1 : begin];
        const double da = glm::dot(plane.n, a) - plane.h;
        const double db = glm::dot(plane.n, b) - plane.h;
        if (da <= 0.0) {
          out.vertices_.push_back(a);
          if (da == 0.0)
            cap.push_back(a);
        }
        if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
          const dvec3 p = a + (b - a) * (da / (da - db));
          out.vertices_.push_back(p);
          cap.push_back(p);
        }
      }
      if (out.vertices_.size() - kept_from >= 3)
        out.face_ends_.push_back(out.vertices_.size());
      else
        out.vertices_.resize(kept_from);
      begin = end;
    }
    if (cap.size() >= 3) {
      order_around(cap, plane.n);
      out.vertices_.insert(out.vertices_.end(), cap.begin(), cap.end());
      out.face_ends_.push_back(out.vertices_.size());
    }
  }

  // Keeps the part with n . x <= h: the world-space step, where allocating
  // is fine.
  void clip(const Halfspace &plane) {
    ConvexPolyhedron out;
    std::vector<dvec3> cap;
    clip_into(plane, out, cap);
    *this = std::move(out);
  }

  template <typename Visit> void for_each_vertex(Visit visit) const {
    for (const dvec3 &v : vertices_)
      visit(v);
  }

private:
  // Puts the points of a convex polygon on a plane of normal n in order.
  static void order_around(std::span<dvec3> points, const dvec3 &n) {
    dvec3 centre(0.0);
    for (const dvec3 &p : points)
      centre += p;
    centre /= double(points.size());
    const dvec3 u = glm::normalize(std::abs(n.x) < 0.9 ? glm::cross(n, dvec3(1, 0, 0))
                                                       : glm::cross(n, dvec3(0, 1, 0)));
    const dvec3 v = glm::cross(n, u);
    const auto angle = [&](const dvec3 &p) {
      return std::atan2(glm::dot(p - centre, v), glm::dot(p - centre, u));
    };
    std::sort(points.begin(), points.end(),
              [&](const dvec3 &a, const dvec3 &b) { return angle(a) < angle(b); });
  }

  std::vector<dvec3> vertices_;
  std::vector<std::size_t> face_ends_; // one past each face's last vertex
};

// A box along three orthonormal axes: the points x with lo_i <= axes_i . x
// <= hi_i. The world's axes make it an axis-aligned box.
struct OrientedBox {
  std::array<dvec3, 3> axes;
  dvec3 lo, hi;

  [[nodiscard]] std::array<dvec3, 8> corners() const {
    std::array<dvec3, 8> c;
    for (int i = 0; i < 8; ++i)
      c[i] = axes[0] * (i & 4 ? hi.x : lo.x) + axes[1] * (i & 2 ? hi.y : lo.y) +
             axes[2] * (i & 1 ? hi.z : lo.z);
    return c;
  }
  // Its six faces' half-spaces.
  [[nodiscard]] std::array<Halfspace, 6> faces() const {
    std::array<Halfspace, 6> f;
    for (int i = 0; i < 3; ++i) {
      f[2 * i] = {axes[i], hi[i]};
      f[2 * i + 1] = {-axes[i], -lo[i]};
    }
    return f;
  }
};

// Supporting half-spaces of B + cone(dirs): candidate normals across the
// pairs of generators (the box's edges and the directions), each kept if no
// generator leaves it. Every half-space kept contains the set, so the cut is
// safe whether or not the list is complete; it is complete (the facets of a
// Minkowski sum lie across pairs of generators), so it is tight.
std::vector<Halfspace> cone_halfspaces(const OrientedBox &box, std::span<const dvec3> dirs,
                                       double margin) {
  std::vector<dvec3> unit;
  for (const dvec3 &d : dirs)
    if (const double len = glm::length(d); len > 0.0)
      unit.push_back(d / len);
  std::vector<dvec3> candidates(box.axes.begin(), box.axes.end());
  for (std::size_t i = 0; i < unit.size(); ++i) {
    for (int axis = 0; axis < 3; ++axis)
      candidates.push_back(glm::cross(box.axes[std::size_t(axis)], unit[i]));
    for (std::size_t j = i + 1; j < unit.size(); ++j)
      candidates.push_back(glm::cross(unit[i], unit[j]));
  }
  const std::array<dvec3, 8> box_corners = box.corners();
  std::vector<Halfspace> planes;
  for (const dvec3 &c : candidates) {
    const double len = glm::length(c);
    if (!(len > 1e-9))
      continue; // (nearly) parallel generators span no plane
    for (const double sign : {1.0, -1.0}) {
      const dvec3 n = sign * c / len;
      // A generator in the plane may lean out of it by rounding; margin
      // covers what that leans out over the scene.
      if (std::any_of(unit.begin(), unit.end(),
                      [&](const dvec3 &d) { return glm::dot(n, d) > 1e-9; }))
        continue;
      if (std::any_of(planes.begin(), planes.end(),
                      [&](const Halfspace &p) { return glm::dot(p.n, n) > 1.0 - 1e-12; }))
        continue;
      double h = -std::numeric_limits<double>::infinity();
      for (const dvec3 &v : box_corners)
        h = std::max(h, glm::dot(n, v));
      planes.push_back({n, h + margin});
    }
  }
  return planes;
}

// A point of the image plane, in pixels: u to the right, v down.
struct Point {
  double u, v;
};

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

// Steps 2 and 3 for one frame after another: each frame's thin lens, the
// tiles marked so far, and the scratch space of the cuts and hulls, kept
// from frame to frame.
class FrameProjector {
public:
  // Room for pieces of up to `vertices` vertices in `faces` faces, and for
  // frames of width x height: after this, start(), add() and finish()
  // allocate nothing.
  void reserve(std::size_t vertices, std::size_t faces, std::uint32_t width, std::uint32_t height) {
    // Two cuts deep at most (behind the lens, then near or far), each
    // growing a piece as clip_into() says.
    std::size_t v = vertices, f = faces;
    for (int cut = 0; cut < 2; ++cut) {
      v += 4 * f;
      f += 1;
    }
    for (ConvexPolyhedron *p : {&front_, &near_, &far_})
      p->reserve(v, f);
    cap_.reserve(2 * f);
    points_.reserve(8 * v); // an octagon per vertex
    hull_.reserve(16 * v);
    const std::size_t tiles_x = (width + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X;
    const std::size_t tiles_y = (height + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y;
    marked_.reserve(tiles_x * tiles_y);
    // Runs of marked tiles alternate with gaps: at most half a row's tiles,
    // and a rectangle ends at most once per run.
    const std::size_t runs = (tiles_x + 1) / 2;
    open_.reserve(runs);
    next_.reserve(runs);
    rects_capacity_ = runs * tiles_y;
  }

  // Forgets the last frame's tiles and takes this one's lens.
  void start(const gpu::FrameParams &frame, const dvec3 &origin) {
    centre_ = dvec3(frame.cam_position) - origin;
    right_ = dvec3(frame.cam_right);
    up_ = dvec3(frame.cam_up);
    forward_ = dvec3(frame.cam_forward);
    aperture_ = frame.lens.x;
    focus_ = frame.lens.y;
    focal_px_ = frame.lens.z;
    filter_px_ = frame.lens.w;
    width_ = frame.image.x;
    height_ = frame.image.y;
    tiles_x_ = (width_ + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X;
    tiles_y_ = (height_ + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y;
    marked_.assign(std::size_t(tiles_x_) * tiles_y_, 0);
  }

  // Marks the pixels that may see a point of `poly`.
  void add(const ConvexPolyhedron &poly) {
    poly.clip_into({-forward_, -glm::dot(forward_, centre_)}, front_, cap_); // behind: no ray
    if (front_.empty())
      return;
    // Within kNearM of the lens a ray is still within the aperture plus a
    // sliver of the field of view; a piece there that a ray may reach is
    // seen across the whole frame.
    constexpr double kNearM = 1e-3;
    front_.clip_into({forward_, glm::dot(forward_, centre_) + kNearM}, near_, cap_);
    if (!near_.empty()) {
      const double reach_aperture = aperture_ * std::max(1.0, std::abs(1.0 - kNearM / focus_));
      const double reach_x =
          reach_aperture + (0.5 * width_ + filter_px_ + 2.0) * kNearM / focal_px_;
      const double reach_y =
          reach_aperture + (0.5 * height_ + filter_px_ + 2.0) * kNearM / focal_px_;
      double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
      near_.for_each_vertex([&](const dvec3 &v) {
        x_lo = std::min(x_lo, glm::dot(right_, v - centre_));
        x_hi = std::max(x_hi, glm::dot(right_, v - centre_));
        y_lo = std::min(y_lo, glm::dot(up_, v - centre_));
        y_hi = std::max(y_hi, glm::dot(up_, v - centre_));
      });
      const bool reachable =
          x_lo <= reach_x && x_hi >= -reach_x && y_lo <= reach_y && y_hi >= -reach_y;
      if (reachable) {
        mark_everywhere();
        return;
      }
    }
    front_.clip_into({-forward_, -glm::dot(forward_, centre_) - kNearM}, far_, cap_);
    if (far_.empty())
      return;
    // Each vertex's blur circle by the octagon around it; the image lies in
    // the convex hull of the octagons.
    constexpr double kOctagon = 1.0823922002923940; // 1 / cos(pi / 8)
    points_.clear();
    bool finite = true;
    far_.for_each_vertex([&](const dvec3 &p) {
      const dvec3 d = p - centre_;
      const double z = glm::dot(forward_, d);
      const double u = 0.5 * width_ + focal_px_ * glm::dot(right_, d) / z;
      const double v = 0.5 * height_ - focal_px_ * glm::dot(up_, d) / z;
      const double blur = focal_px_ * aperture_ * std::abs(1.0 / focus_ - 1.0 / z) * kOctagon;
      finite = finite && std::isfinite(u) && std::isfinite(v) && std::isfinite(blur);
      for (const Point &corner : kOctagonCorners)
        points_.push_back({u + blur * corner.u, v + blur * corner.v});
    });
    if (!finite) {
      mark_everywhere(); // unknown
      return;
    }
    convex_hull(points_, hull_);
    mark_polygon(hull_);
  }

  // The marked tiles as rectangles, into `region` (its storage reused).
  void finish(InfluenceRegion &region);

  [[nodiscard]] std::size_t rects_capacity() const { return rects_capacity_; }

private:
  // Marks every tile: where a piece's image is not known.
  void mark_everywhere() { std::fill(marked_.begin(), marked_.end(), std::uint8_t(1)); }

  // Marks the tiles of the pixels whose samples (the pixel's centre within
  // half the filter width, and one pixel more for the rays' rounding) can
  // fall in a convex polygon (image coordinates, in order), a row of
  // tiles at a time: its x-range within the row's band of sample positions.
  void mark_polygon(std::span<const Point> hull) {
    if (hull.empty())
      return;
    double v_lo = INFINITY, v_hi = -INFINITY;
    for (const Point &p : hull) {
      v_lo = std::min(v_lo, p.v);
      v_hi = std::max(v_hi, p.v);
    }
    const double reach = kReachPx + 0.5 * filter_px_;
    for (std::uint32_t ty = 0; ty < tiles_y_; ++ty) {
      // The sample positions of the row's pixels: their centres within reach.
      const double band_lo = double(ty * CAMHEAD_TILE_Y) + 0.5 - reach;
      const double band_hi = double(std::min((ty + 1) * CAMHEAD_TILE_Y, height_)) - 0.5 + reach;
      if (band_hi < v_lo || band_lo > v_hi)
        continue;
      double u_lo = INFINITY, u_hi = -INFINITY;
      const auto take = [&](double u) {
        u_lo = std::min(u_lo, u);
        u_hi = std::max(u_hi, u);
      };
      for (std::size_t i = 0; i < hull.size(); ++i) {
        const Point &a = hull[i];
        const Point &b = hull[(i + 1) % hull.size()];
        if (a.v >= band_lo && a.v <= band_hi)
          take(a.u);
        for (const double line : {band_lo, band_hi})
          if ((a.v < line && b.v > line) || (a.v > line && b.v < line))
            take(a.u + (b.u - a.u) * ((line - a.v) / (b.v - a.v)));
      }
      if (!(u_lo <= u_hi))
        continue;
      const double x0 = std::max(0.0, std::floor(u_lo - 0.5 - reach));
      const double x1 = std::min(double(width_) - 1, std::ceil(u_hi - 0.5 + reach));
      if (!(x0 <= x1))
        continue;
      for (auto tx = std::uint32_t(x0) / CAMHEAD_TILE_X; tx <= std::uint32_t(x1) / CAMHEAD_TILE_X;
           ++tx)
        marked_[std::size_t(ty) * tiles_x_ + tx] = 1;
    }
  }

  // A pixel of margin for the rays' rounding, beyond the pixel filter.
  static constexpr double kReachPx = 1.0;

  // The unit octagon's corners, at multiples of 45 degrees.
  static constexpr double kHalfRoot2 = 0.70710678118654752;
  static constexpr Point kOctagonCorners[8] = {
      {1, 0},  {kHalfRoot2, kHalfRoot2},   {0, 1},  {-kHalfRoot2, kHalfRoot2},
      {-1, 0}, {-kHalfRoot2, -kHalfRoot2}, {0, -1}, {kHalfRoot2, -kHalfRoot2}};

  // A run of marked tiles [tx0, tx1), open since row ty0.
  struct Open {
    std::uint32_t tx0, tx1, ty0;
  };

  dvec3 centre_{}, right_{}, up_{}, forward_{};
  double aperture_ = 0.0, focus_ = 0.0, focal_px_ = 0.0, filter_px_ = 0.0;
  std::uint32_t width_ = 0, height_ = 0, tiles_x_ = 0, tiles_y_ = 0;
  std::vector<std::uint8_t> marked_;
  ConvexPolyhedron front_, near_, far_;
  std::vector<dvec3> cap_;
  std::vector<Point> points_, hull_;
  std::vector<Open> open_, next_;
  std::size_t rects_capacity_ = 0;
};

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

// Tangent planes around a sphere of `radius` (margin included) at `centre`,
// along 12 edge and 8 corner directions: its box with the corners and edges
// cut off, a third of the box's volume beyond the sphere instead of half.
std::vector<Halfspace> sphere_cuts(const dvec3 &centre, double radius) {
  std::vector<Halfspace> cuts;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        const int nonzero = (x != 0) + (y != 0) + (z != 0);
        if (nonzero < 2)
          continue; // the box's own faces, and the centre
        const dvec3 n = glm::normalize(dvec3(x, y, z));
        cuts.push_back({n, glm::dot(n, centre) + radius});
      }
  return cuts;
}

// Two unit vectors orthogonal to unit `a` and to each other.
std::pair<dvec3, dvec3> orthogonal_pair(const dvec3 &a) {
  const dvec3 u = glm::normalize(std::abs(a.x) < 0.9 ? glm::cross(a, dvec3(1, 0, 0))
                                                     : glm::cross(a, dvec3(0, 1, 0)));
  return {u, glm::cross(a, u)};
}

// The shadow of a sphere from a point light or a sun, bounded by 16 planes
// tangent to its circular shadow cone or cylinder (1.3 % more area than the
// circle) and by where it starts; none for a light inside the sphere (the
// whole receiver) or an area light (cone_halfspaces() over its box).
std::optional<std::vector<Halfspace>> sphere_shadow_cuts(const dvec3 &centre, double radius,
                                                         const struct LightShape &light);

// The object's two boxes, each grown by `margin`: aligned with the world,
// and along its own axes (none when those are the world's).
OrientedBox world_box_of(const ObjectBounds &o, double margin) {
  return {
      {dvec3(1, 0, 0), dvec3(0, 1, 0), dvec3(0, 0, 1)}, dvec3(o.lo) - margin, dvec3(o.hi) + margin};
}
std::optional<OrientedBox> own_box_of(const ObjectBounds &o, double margin) {
  if (o.axes == glm::mat3(1.0f))
    return std::nullopt;
  return OrientedBox{{dvec3(o.axes[0]), dvec3(o.axes[1]), dvec3(o.axes[2])},
                     dvec3(o.axis_lo) - margin,
                     dvec3(o.axis_hi) + margin};
}

// Where the object can be: its world box, cut down to its own box, and for a
// sphere to its round shape.
ConvexPolyhedron object_polyhedron(const ObjectBounds &o, double margin) {
  const OrientedBox world = world_box_of(o, margin);
  ConvexPolyhedron poly = ConvexPolyhedron::box(world.lo, world.hi);
  if (const std::optional<OrientedBox> own = own_box_of(o, margin))
    for (const Halfspace &h : own->faces())
      poly.clip(h);
  if (o.sphere)
    for (const Halfspace &h : sphere_cuts(dvec3(o.centre), double(o.radius) + margin))
      poly.clip(h);
  return poly;
}

// Where the shadow rays toward a light end: the light's corners, or a sun's
// direction of travel; and the side an area light shines on.
struct LightShape {
  std::vector<dvec3> points;
  std::optional<dvec3> travel;
  std::optional<Halfspace> lit;
  bool anywhere = false; // no cut: the whole receiver
};

std::optional<std::vector<Halfspace>> sphere_shadow_cuts(const dvec3 &centre, double radius,
                                                         const LightShape &light) {
  constexpr int kSides = 16;
  std::vector<Halfspace> cuts;
  if (light.travel) { // a cylinder along the sun's direction of travel
    const dvec3 t = glm::normalize(*light.travel);
    const auto [u, v] = orthogonal_pair(t);
    for (int k = 0; k < kSides; ++k) {
      const double phi = 2.0 * 3.14159265358979323846 * k / kSides;
      const dvec3 n = std::cos(phi) * u + std::sin(phi) * v;
      cuts.push_back({n, glm::dot(n, centre) + radius});
    }
    cuts.push_back({-t, -glm::dot(t, centre) + radius}); // not before the sphere
    return cuts;
  }
  if (light.points.size() != 1)
    return std::nullopt;
  const dvec3 &l = light.points.front();
  const double distance = glm::length(centre - l);
  if (!(distance > radius))
    return std::nullopt;
  // Planes through the light, each tangent to the cone of half-angle alpha
  // along one generator: n = u_k cos(alpha) - a sin(alpha) leaves every
  // direction within alpha of the axis a behind it.
  // Each half-space contains the whole cone (a direction at beta <= alpha
  // from the axis, toward w, has n . d = cos(alpha) sin(beta) (u_k . w) -
  // sin(alpha) cos(beta) <= sin(beta - alpha) <= 0), so their intersection,
  // the circumscribed 16-gon's cone, does too.
  const dvec3 a = (centre - l) / distance;
  const double sine = radius / distance, cosine = std::sqrt(1.0 - sine * sine);
  const auto [u, v] = orthogonal_pair(a);
  for (int k = 0; k < kSides; ++k) {
    const double phi = 2.0 * 3.14159265358979323846 * k / kSides;
    const dvec3 n = (std::cos(phi) * u + std::sin(phi) * v) * cosine - a * sine;
    cuts.push_back({n, glm::dot(n, l)});
  }
  cuts.push_back({-a, -glm::dot(a, l) - (distance - radius)}); // beyond the sphere's near side
  return cuts;
}

std::optional<LightShape> light_shape(const gpu::Light &light, double margin) {
  const glm::vec3 emission(light.emission);
  if (!(emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f))
    return std::nullopt; // direct_light() skips it
  LightShape shape;
  const dvec3 position(light.position);
  switch (glm::floatBitsToUint(light.position.w)) {
  case LIGHT_POINT:
    shape.points = {position};
    break;
  case LIGHT_AREA: {
    const dvec3 u = 0.5 * dvec3(light.axis_u), v = 0.5 * dvec3(light.axis_v);
    shape.points = {position - u - v, position + u - v, position + u + v, position - u + v};
    const dvec3 n(light.normal);
    shape.lit = Halfspace{-n, -glm::dot(n, position) + margin};
    break;
  }
  case LIGHT_SUN:
    shape.travel = dvec3(light.normal);
    break;
  default:
    // Not a kind compile_light() makes: were one added and forgotten here,
    // its shadows could fall anywhere on a receiver.
    shape.anywhere = true;
    break;
  }
  return shape;
}

// A world-space piece of the region (step 1): where a virtual object can
// change what a camera ray brings back, in every frame or, for a shadow,
// while its light is one of the frame's.
struct WorldPiece {
  ConvexPolyhedron where;
  std::size_t light = 0; // lights a frame must have for it; 0 for none
};

// Step 1 for `scene` with everything grown by `margin`.
std::vector<WorldPiece> world_pieces(const CompiledScene &scene, double margin) {
  std::vector<WorldPiece> pieces;
  if (std::none_of(scene.objects.begin(), scene.objects.end(),
                   [](const ObjectBounds &o) { return !o.real; }))
    return pieces; // nothing virtual: the camera image everywhere
  for (const ObjectBounds &o : scene.objects)
    if (!o.real || o.specular)
      pieces.push_back({object_polyhedron(o, margin), 0});

  for (std::size_t li = 0; li < scene.lights.size(); ++li) {
    const std::optional<LightShape> shape = light_shape(scene.lights[li], margin);
    if (!shape)
      continue;
    for (const ObjectBounds &caster : scene.objects) {
      if (caster.real)
        continue;
      std::vector<Halfspace> cut;
      std::optional<std::vector<Halfspace>> round;
      if (caster.sphere && !shape->anywhere)
        round = sphere_shadow_cuts(dvec3(caster.centre), double(caster.radius) + margin, *shape);
      if (round) {
        cut = std::move(*round);
      } else if (!shape->anywhere) {
        // The shadow of each of the caster's boxes contains its shadow.
        const std::optional<OrientedBox> own = own_box_of(caster, margin);
        for (const std::optional<OrientedBox> &box :
             {std::optional(world_box_of(caster, margin)), own}) {
          if (!box)
            continue;
          std::vector<dvec3> dirs;
          if (shape->travel)
            dirs.push_back(*shape->travel);
          for (const dvec3 &l : shape->points)
            for (const dvec3 &c : box->corners())
              dirs.push_back(c - l);
          const std::vector<Halfspace> planes = cone_halfspaces(*box, dirs, margin);
          cut.insert(cut.end(), planes.begin(), planes.end());
        }
      }
      if (shape->lit)
        cut.push_back(*shape->lit);
      for (const ObjectBounds &o : scene.objects) {
        if (!o.real || !o.shaded)
          continue;
        ConvexPolyhedron poly = object_polyhedron(o, margin);
        for (const Halfspace &h : cut) {
          poly.clip(h);
          if (poly.empty())
            break;
        }
        if (!poly.empty())
          pieces.push_back({std::move(poly), li + 1});
      }
    }
  }
  return pieces;
}

} // namespace

struct InfluenceRegionBuilder::State {
  explicit State(const CompiledScene &s) : scene(s) {
    for (const ObjectBounds &o : scene.objects)
      object_scale = std::max({object_scale, glm::length(dvec3(o.lo)), glm::length(dvec3(o.hi))});
  }

  // Step 1 for a scene seen from up to `scale` metres from its origin, and
  // room for steps 2 and 3 to project it into width x height frames.
  void build_pieces(double scale) {
    // Above the kernel's ray offsets (CAMHEAD_RAY_EPSILON x (1 + |p|)) and
    // the float rounding of hits, at the scale of the scene.
    pieces = world_pieces(scene, 1e-3 * (1.0 + scale));
    pieces_scale = scale;
    reserved_width = 0; // the pieces' sizes changed
  }

  void reserve(std::uint32_t width, std::uint32_t height) {
    std::size_t vertices = 0, faces = 0;
    for (const WorldPiece &p : pieces) {
      vertices = std::max(vertices, p.where.vertex_storage());
      faces = std::max(faces, p.where.faces());
    }
    projector.reserve(vertices, faces, width, height);
    region.rects.reserve(std::max<std::size_t>(projector.rects_capacity(), 1));
    reserved_width = width;
    reserved_height = height;
  }

  const CompiledScene &scene;
  double object_scale = 0.0;
  double pieces_scale = -1.0; // none built
  std::vector<WorldPiece> pieces;
  FrameProjector projector;
  std::uint32_t reserved_width = 0, reserved_height = 0;
  InfluenceRegion region;
};

InfluenceRegionBuilder::InfluenceRegionBuilder(const CompiledScene &scene)
    : state_(std::make_unique<State>(scene)) {}

InfluenceRegionBuilder::~InfluenceRegionBuilder() = default;

const InfluenceRegion &InfluenceRegionBuilder::build(const gpu::FrameParams &frame) {
  State &s = *state_;
  if (frame.image.z == 0)
    return whole_frame(frame.image.x, frame.image.y);
  const double scale =
      std::max(s.object_scale, glm::length(dvec3(frame.cam_position) - dvec3(s.scene.origin)));
  if (!std::isfinite(scale))
    return whole_frame(frame.image.x, frame.image.y); // a camera nowhere: unknown
  // The first build for the scale there is; a later one, for a camera gone
  // further out, with a quarter more, so that a camera moving about rarely
  // rebuilds (a larger margin is safe, a little more is traced).
  if (scale > s.pieces_scale)
    s.build_pieces(s.pieces_scale < 0.0 ? scale : 1.25 * scale);
  if (s.reserved_width != frame.image.x || s.reserved_height != frame.image.y)
    s.reserve(frame.image.x, frame.image.y);
  s.projector.start(frame, dvec3(s.scene.origin));
  const std::size_t lights = std::min<std::size_t>(frame.image.w, s.scene.lights.size());
  for (const WorldPiece &piece : s.pieces)
    if (piece.light <= lights)
      s.projector.add(piece.where);
  s.projector.finish(s.region);
  return s.region;
}

const InfluenceRegion &InfluenceRegionBuilder::whole_frame(std::uint32_t width,
                                                           std::uint32_t height) {
  InfluenceRegion &region = state_->region;
  region.width = width;
  region.height = height;
  region.rects.clear();
  if (width > 0 && height > 0)
    region.rects.push_back({0, 0, width, height});
  return region;
}

std::uint64_t InfluenceRegion::pixels() const {
  std::uint64_t sum = 0;
  for (const PixelRect &r : rects)
    sum += r.pixels();
  return sum;
}

InfluenceRegion whole_frame_region(std::uint32_t width, std::uint32_t height) {
  InfluenceRegion region;
  region.width = width;
  region.height = height;
  if (width > 0 && height > 0)
    region.rects.push_back({0, 0, width, height});
  return region;
}

InfluenceRegion influence_region(const CompiledScene &scene, const gpu::FrameParams &frame) {
  InfluenceRegionBuilder builder(scene);
  return builder.build(frame);
}

} // namespace camhead::renderer
