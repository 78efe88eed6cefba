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
// order), cut down one half-space at a time.
class ConvexPolyhedron {
public:
  static ConvexPolyhedron box(const dvec3 &lo, const dvec3 &hi) {
    std::array<dvec3, 8> c;
    for (int i = 0; i < 8; ++i)
      c[i] = dvec3(i & 4 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 1 ? hi.z : lo.z);
    constexpr int kFaces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                  {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    ConvexPolyhedron p;
    for (const auto &f : kFaces)
      p.faces_.push_back({c[f[0]], c[f[1]], c[f[2]], c[f[3]]});
    return p;
  }

  [[nodiscard]] bool empty() const { return faces_.empty(); }

  // Keeps the part with n . x <= h, closed by a new face on the plane.
  void clip(const Halfspace &plane) {
    std::vector<std::vector<dvec3>> kept;
    std::vector<dvec3> cap;
    for (const std::vector<dvec3> &face : faces_) {
      std::vector<dvec3> out;
      for (std::size_t i = 0; i < face.size(); ++i) {
        const dvec3 &a = face[i];
        const dvec3 &b = face[(i + 1) % face.size()];
        const double da = glm::dot(plane.n, a) - plane.h;
        const double db = glm::dot(plane.n, b) - plane.h;
        if (da <= 0.0) {
          out.push_back(a);
          if (da == 0.0)
            cap.push_back(a);
        }
        if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
          const dvec3 p = a + (b - a) * (da / (da - db));
          out.push_back(p);
          cap.push_back(p);
        }
      }
      if (out.size() >= 3)
        kept.push_back(std::move(out));
    }
    if (cap.size() >= 3)
      kept.push_back(order_around(std::move(cap), plane.n));
    faces_ = std::move(kept);
  }

  template <typename Visit> void for_each_vertex(Visit visit) const {
    for (const std::vector<dvec3> &face : faces_)
      for (const dvec3 &v : face)
        visit(v);
  }

private:
  // The points of a convex polygon on a plane of normal n, in order.
  static std::vector<dvec3> order_around(std::vector<dvec3> points, const dvec3 &n) {
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
    return points;
  }

  std::vector<std::vector<dvec3>> faces_;
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

// Andrew's monotone chain: the hull's corners in order (collinear points
// dropped); fewer than three points come back as they are.
std::vector<Point> convex_hull(std::vector<Point> points) {
  std::sort(points.begin(), points.end(),
            [](const Point &a, const Point &b) { return a.u != b.u ? a.u < b.u : a.v < b.v; });
  if (points.size() < 3)
    return points;
  const auto turn = [](const Point &o, const Point &a, const Point &b) {
    return (a.u - o.u) * (b.v - o.v) - (a.v - o.v) * (b.u - o.u);
  };
  std::vector<Point> hull(2 * points.size());
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
  return hull;
}

// The frame's thin lens in the compiled scene's frame, and the tiles marked
// so far.
class RegionBuilder {
public:
  RegionBuilder(const gpu::FrameParams &frame, const dvec3 &origin)
      : centre_(dvec3(frame.cam_position) - origin), right_(dvec3(frame.cam_right)),
        up_(dvec3(frame.cam_up)), forward_(dvec3(frame.cam_forward)), aperture_(frame.lens.x),
        focus_(frame.lens.y), focal_px_(frame.lens.z), filter_px_(frame.lens.w),
        width_(frame.image.x), height_(frame.image.y),
        tiles_x_((width_ + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X),
        tiles_y_((height_ + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y),
        marked_(std::size_t(tiles_x_) * tiles_y_, 0) {}

  // Marks the pixels that may see a point of `poly` (consumed).
  void add(ConvexPolyhedron poly) {
    poly.clip({-forward_, -glm::dot(forward_, centre_)}); // behind the lens: no camera ray
    if (poly.empty())
      return;
    // Within kNearM of the lens a ray is still within the aperture plus a
    // sliver of the field of view; a piece there that a ray may reach is
    // seen across the whole frame.
    constexpr double kNearM = 1e-3;
    ConvexPolyhedron near = poly;
    near.clip({forward_, glm::dot(forward_, centre_) + kNearM});
    if (!near.empty()) {
      const double reach_aperture = aperture_ * std::max(1.0, std::abs(1.0 - kNearM / focus_));
      const double reach_x =
          reach_aperture + (0.5 * width_ + filter_px_ + 2.0) * kNearM / focal_px_;
      const double reach_y =
          reach_aperture + (0.5 * height_ + filter_px_ + 2.0) * kNearM / focal_px_;
      double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
      near.for_each_vertex([&](const dvec3 &v) {
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
    poly.clip({-forward_, -glm::dot(forward_, centre_) - kNearM});
    if (poly.empty())
      return;
    // Each vertex's blur circle by the octagon around it; the image lies in
    // the convex hull of the octagons.
    constexpr double kOctagon = 1.0823922002923940; // 1 / cos(pi / 8)
    std::vector<Point> points;
    bool finite = true;
    poly.for_each_vertex([&](const dvec3 &p) {
      const dvec3 d = p - centre_;
      const double z = glm::dot(forward_, d);
      const double u = 0.5 * width_ + focal_px_ * glm::dot(right_, d) / z;
      const double v = 0.5 * height_ - focal_px_ * glm::dot(up_, d) / z;
      const double blur = focal_px_ * aperture_ * std::abs(1.0 / focus_ - 1.0 / z) * kOctagon;
      finite = finite && std::isfinite(u) && std::isfinite(v) && std::isfinite(blur);
      for (int k = 0; k < 8; ++k) {
        const double phi = 0.7853981633974483 * k;
        points.push_back({u + blur * std::cos(phi), v + blur * std::sin(phi)});
      }
    });
    if (!finite) {
      mark_everywhere(); // unknown
      return;
    }
    mark_polygon(convex_hull(std::move(points)));
  }

  [[nodiscard]] InfluenceRegion region() const;

private:
  // Marks every tile: where a piece's image is not known.
  void mark_everywhere() { std::fill(marked_.begin(), marked_.end(), std::uint8_t(1)); }

  // Marks the tiles of the pixels whose samples (the pixel's centre within
  // half the filter width, and one pixel more for the rays' rounding) can
  // fall in a convex polygon (image coordinates, in order), a row of
  // tiles at a time: its x-range within the row's band of sample positions.
  void mark_polygon(const std::vector<Point> &hull) {
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

  dvec3 centre_, right_, up_, forward_;
  double aperture_, focus_, focal_px_, filter_px_;
  std::uint32_t width_, height_, tiles_x_, tiles_y_;
  std::vector<std::uint8_t> marked_;
};

InfluenceRegion RegionBuilder::region() const {
  InfluenceRegion region;
  region.width = width_;
  region.height = height_;
  const auto pixel_rect = [&](std::uint32_t tx0, std::uint32_t tx1, std::uint32_t ty0,
                              std::uint32_t ty1) {
    return PixelRect{tx0 * CAMHEAD_TILE_X, ty0 * CAMHEAD_TILE_Y,
                     std::min(tx1 * CAMHEAD_TILE_X, width_),
                     std::min(ty1 * CAMHEAD_TILE_Y, height_)};
  };
  // Runs of tiles, a row at a time; a run that repeats the one above
  // extends its rectangle.
  struct Open {
    std::uint32_t tx0, tx1, ty0;
  };
  std::vector<Open> open, next;
  for (std::uint32_t ty = 0; ty <= tiles_y_; ++ty) {
    next.clear();
    std::uint32_t tx = 0;
    while (ty < tiles_y_ && tx < tiles_x_) {
      if (!marked_[std::size_t(ty) * tiles_x_ + tx]) {
        ++tx;
        continue;
      }
      const std::uint32_t start = tx;
      while (tx < tiles_x_ && marked_[std::size_t(ty) * tiles_x_ + tx])
        ++tx;
      const auto above = std::find_if(open.begin(), open.end(),
                                      [&](const Open &o) { return o.tx0 == start && o.tx1 == tx; });
      next.push_back({start, tx, above != open.end() ? above->ty0 : ty});
      if (above != open.end())
        open.erase(above);
    }
    for (const Open &o : open) // not continued in this row
      region.rects.push_back(pixel_rect(o.tx0, o.tx1, o.ty0, ty));
    std::swap(open, next);
  }
  std::sort(region.rects.begin(), region.rects.end(), [](const PixelRect &a, const PixelRect &b) {
    return a.y0 != b.y0 ? a.y0 < b.y0 : a.x0 < b.x0;
  });
  return region;
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

} // namespace

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
  if (frame.image.z == 0)
    return whole_frame_region(frame.image.x, frame.image.y);
  // Above the kernel's ray offsets (CAMHEAD_RAY_EPSILON x (1 + |p|)) and the
  // float rounding of hits, at the scale of the scene.
  double scale = glm::length(dvec3(frame.cam_position) - dvec3(scene.origin));
  for (const ObjectBounds &o : scene.objects)
    scale = std::max({scale, glm::length(dvec3(o.lo)), glm::length(dvec3(o.hi))});
  const double margin = 1e-3 * (1.0 + scale);

  RegionBuilder builder(frame, dvec3(scene.origin));
  if (std::none_of(scene.objects.begin(), scene.objects.end(),
                   [](const ObjectBounds &o) { return !o.real; }))
    return builder.region();
  for (const ObjectBounds &o : scene.objects)
    if (!o.real || o.specular)
      builder.add(object_polyhedron(o, margin));

  const std::size_t lights = std::min<std::size_t>(frame.image.w, scene.lights.size());
  for (std::size_t li = 0; li < lights; ++li) {
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
          builder.add(std::move(poly));
      }
    }
  }
  return builder.region();
}

} // namespace camhead::renderer
