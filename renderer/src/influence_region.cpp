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
// here, and steps 2 and 3 run per frame in storage it keeps
// (region_geometry.h's FrameProjector, with the polyhedra both steps cut).
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

#include "region_geometry.h"

namespace camhead::renderer {
namespace {

using glm::dvec3;
using region_geometry::ConvexPolyhedron;
using region_geometry::FrameProjector;
using region_geometry::Halfspace;

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

const InfluenceRegion &InfluenceRegionBuilder::none(std::uint32_t width, std::uint32_t height) {
  InfluenceRegion &region = state_->region;
  region.width = width;
  region.height = height;
  region.rects.clear();
  return region;
}

std::uint64_t InfluenceRegion::pixels() const {
  std::uint64_t sum = 0;
  for (const PixelRect &r : rects)
    sum += r.pixels();
  return sum;
}

std::size_t max_region_rects(std::uint32_t width, std::uint32_t height) {
  return std::size_t((width + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X) *
         ((height + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y);
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
