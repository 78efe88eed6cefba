// The influence region's geometry (influence_region.cpp): convex polyhedra
// cut by half-spaces (step 1 builds them, and each frame cuts them at the
// lens), and the projection of a frame's pieces through its thin lens onto
// tiles (steps 2 and 3), in storage kept from frame to frame.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/frame_settings.h"
#include "camhead/renderer/gpu_layout.h"
#include "camhead/renderer/influence_region.h"
#include "lens_model_math.h"

namespace camhead::renderer::region_geometry {

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

// A point of the image plane, in pixels: u to the right, v down.
struct Point {
  double u, v;
};

// Andrew's monotone chain: the corners of the hull of `points` (sorted in
// place) in order, into `hull` (collinear points dropped); fewer than three
// points come back as they are. `hull` needs room for 2 points.size().
void convex_hull(std::span<Point> points, std::vector<Point> &hull);

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
    // An octagon per vertex; through a lens model, the hull's edges in steps.
    points_.reserve(kMostLensPoints + 8 * v + 8);
    hull_.reserve(2 * points_.capacity());
    clipped_.reserve(16 * v + 8);
    clipping_.reserve(16 * v + 8);
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
    lens_model_ = has_lens_model(frame);
    if (lens_model_) {
      frame_ = frame;
      bound_lens();
    }
  }

  // Marks the pixels that may see a point of `poly`.
  void add(const ConvexPolyhedron &poly) {
    if (lens_model_ && !lens_invertible_) {
      mark_everywhere(); // a lens that folds over: where anything lands is unknown
      return;
    }
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
      // The frame's half-width and half-height on the ideal image plane:
      // through a lens model, the bounds of its preimage.
      const double half_x = lens_model_ ? std::max(-lens_lo_.u, lens_hi_.u)
                                        : (0.5 * width_ + filter_px_ + 2.0) / focal_px_;
      const double half_y = lens_model_ ? std::max(-lens_lo_.v, lens_hi_.v)
                                        : (0.5 * height_ + filter_px_ + 2.0) / focal_px_;
      const double reach_x = reach_aperture + half_x * kNearM;
      const double reach_y = reach_aperture + half_y * kNearM;
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
    if (lens_model_) {
      add_through_lens(kOctagon);
      return;
    }
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
  // A piece seen through the frame's lens model (renderer/shaders/
  // lens_model.glsl): the hull of its blur octagons on the ideal image plane
  // (normalised), cut to the rectangle that holds every sample position's
  // preimage (bound_lens), then its edges taken through the lens in steps of
  // at most kLensStepPx: the hull of those points, grown by kChordPx, holds
  // the piece's distorted image (the lens bends an edge between two steps
  // by far less: its sagitta over 4 px, a barrel of k1 = -0.3 at 700 px, is
  // under a hundredth of a pixel).
  void add_through_lens(double octagon) {
    points_.clear();
    bool finite = true;
    far_.for_each_vertex([&](const dvec3 &p) {
      const dvec3 d = p - centre_;
      const double z = glm::dot(forward_, d);
      const double x = glm::dot(right_, d) / z, y = -glm::dot(up_, d) / z;
      const double blur = aperture_ * std::abs(1.0 / focus_ - 1.0 / z) * octagon;
      finite = finite && std::isfinite(x) && std::isfinite(y) && std::isfinite(blur);
      for (const Point &corner : kOctagonCorners)
        points_.push_back({x + blur * corner.u, y + blur * corner.v});
    });
    if (!finite) {
      mark_everywhere(); // unknown
      return;
    }
    convex_hull(points_, hull_);
    clip_to_lens_bounds();
    if (clipped_.empty())
      return;
    double perimeter_px = 0.0;
    for (std::size_t i = 0; i < clipped_.size(); ++i) {
      const Point &a = clipped_[i], &b = clipped_[(i + 1) % clipped_.size()];
      perimeter_px += std::hypot(b.u - a.u, b.v - a.v) * focal_px_;
    }
    const double step_px = std::max(kLensStepPx, perimeter_px / double(kMostLensPoints));
    points_.clear();
    for (std::size_t i = 0; i < clipped_.size(); ++i) {
      const Point &a = clipped_[i], &b = clipped_[(i + 1) % clipped_.size()];
      const double steps =
          std::max(1.0, std::ceil(std::hypot(b.u - a.u, b.v - a.v) * focal_px_ / step_px));
      for (double k = 0.0; k < steps; k += 1.0) {
        const double t = k / steps;
        const glm::vec2 pixel = ideal_to_pixel(
            frame_, glm::vec2(float(a.u + (b.u - a.u) * t), float(a.v + (b.v - a.v) * t)));
        points_.push_back({pixel.x, pixel.y});
      }
    }
    convex_hull(points_, hull_);
    mark_polygon(hull_, kChordPx);
  }

  // The rectangle of the ideal image plane that holds the preimage of every
  // sample position (the frame grown by the reach): the border's, taken back
  // through the lens every few pixels, when the lens is one-to-one there
  // (its Jacobian's determinant positive on a grid, and each border point's
  // preimage going back to it). A lens that folds over inside the frame, as
  // a strong barrel polynomial does past its turning radius, has no such
  // rectangle: every tile is marked.
  void bound_lens() {
    const double grow = kReachPx + 0.5 * filter_px_ + 1.0;
    const double u0 = -grow, u1 = double(width_) + grow;
    const double v0 = -grow, v1 = double(height_) + grow;
    lens_lo_ = {INFINITY, INFINITY};
    lens_hi_ = {-INFINITY, -INFINITY};
    lens_invertible_ = true;
    const auto take = [&](double u, double v) {
      const glm::vec2 ideal = pixel_to_ideal(frame_, glm::vec2(float(u), float(v)));
      const glm::vec2 back = ideal_to_pixel(frame_, ideal);
      if (!(std::abs(double(back.x) - u) < 0.01 && std::abs(double(back.y) - v) < 0.01))
        lens_invertible_ = false;
      lens_lo_ = {std::min(lens_lo_.u, double(ideal.x)), std::min(lens_lo_.v, double(ideal.y))};
      lens_hi_ = {std::max(lens_hi_.u, double(ideal.x)), std::max(lens_hi_.v, double(ideal.y))};
    };
    constexpr double kBorderStepPx = 4.0;
    for (double u = u0; u < u1 + kBorderStepPx; u += kBorderStepPx) {
      take(std::min(u, u1), v0);
      take(std::min(u, u1), v1);
    }
    for (double v = v0; v < v1 + kBorderStepPx; v += kBorderStepPx) {
      take(u0, std::min(v, v1));
      take(u1, std::min(v, v1));
    }
    // A hair more, for the float arithmetic of the kernels' own preimages.
    const double slack = 1e-4 * std::max(lens_hi_.u - lens_lo_.u, lens_hi_.v - lens_lo_.v);
    lens_lo_ = {lens_lo_.u - slack, lens_lo_.v - slack};
    lens_hi_ = {lens_hi_.u + slack, lens_hi_.v + slack};
    constexpr int kGrid = 16;
    for (int j = 0; j <= kGrid && lens_invertible_; ++j)
      for (int i = 0; i <= kGrid && lens_invertible_; ++i) {
        const double x = lens_lo_.u + (lens_hi_.u - lens_lo_.u) * i / kGrid;
        const double y = lens_lo_.v + (lens_hi_.v - lens_lo_.v) * j / kGrid;
        const glm::vec3 jac = cpu::LensModelMath{}.lens_jacobian(
            glm::vec2(float(x), float(y)), frame_.distortion, frame_.projection.w);
        lens_invertible_ = double(jac.x) * jac.y - double(jac.z) * jac.z > 0.0;
      }
    if (!std::isfinite(lens_lo_.u + lens_lo_.v + lens_hi_.u + lens_hi_.v))
      lens_invertible_ = false;
  }

  // hull_ cut to the rectangle lens_lo_..lens_hi_ (Sutherland-Hodgman), into
  // clipped_.
  void clip_to_lens_bounds() {
    clipped_.assign(hull_.begin(), hull_.end());
    const auto cut = [&](auto inside, auto cross) {
      clipping_.clear();
      for (std::size_t i = 0; i < clipped_.size(); ++i) {
        const Point &a = clipped_[i], &b = clipped_[(i + 1) % clipped_.size()];
        if (inside(a))
          clipping_.push_back(a);
        if (inside(a) != inside(b))
          clipping_.push_back(cross(a, b));
      }
      clipped_.swap(clipping_);
    };
    const auto at_u = [](double u) {
      return [u](const Point &a, const Point &b) {
        return Point{u, a.v + (b.v - a.v) * ((u - a.u) / (b.u - a.u))};
      };
    };
    const auto at_v = [](double v) {
      return [v](const Point &a, const Point &b) {
        return Point{a.u + (b.u - a.u) * ((v - a.v) / (b.v - a.v)), v};
      };
    };
    cut([&](const Point &p) { return p.u >= lens_lo_.u; }, at_u(lens_lo_.u));
    cut([&](const Point &p) { return p.u <= lens_hi_.u; }, at_u(lens_hi_.u));
    cut([&](const Point &p) { return p.v >= lens_lo_.v; }, at_v(lens_lo_.v));
    cut([&](const Point &p) { return p.v <= lens_hi_.v; }, at_v(lens_hi_.v));
  }

  // Marks every tile: where a piece's image is not known.
  void mark_everywhere() { std::fill(marked_.begin(), marked_.end(), std::uint8_t(1)); }

  // Marks the tiles of the pixels whose samples (the pixel's centre within
  // half the filter width, and one pixel more for the rays' rounding) can
  // fall in a convex polygon (image coordinates, in order), a row of
  // tiles at a time: its x-range within the row's band of sample positions.
  void mark_polygon(std::span<const Point> hull, double extra_reach_px = 0.0) {
    if (hull.empty())
      return;
    double v_lo = INFINITY, v_hi = -INFINITY;
    for (const Point &p : hull) {
      v_lo = std::min(v_lo, p.v);
      v_hi = std::max(v_hi, p.v);
    }
    const double reach = kReachPx + 0.5 * filter_px_ + extra_reach_px;
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
  // Through a lens model: the longest step along a hull's edge, the points
  // an edge may take (a longer hull takes longer steps), and the margin for
  // the lens's bending of an edge between two steps.
  static constexpr double kLensStepPx = 4.0;
  static constexpr std::size_t kMostLensPoints = 2048;
  static constexpr double kChordPx = 0.25;

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
  bool lens_model_ = false, lens_invertible_ = false;
  gpu::FrameParams frame_{}; // with a lens model: its projection
  Point lens_lo_{}, lens_hi_{};
  std::vector<Point> clipped_, clipping_;
  std::uint32_t width_ = 0, height_ = 0, tiles_x_ = 0, tiles_y_ = 0;
  std::vector<std::uint8_t> marked_;
  ConvexPolyhedron front_, near_, far_;
  std::vector<dvec3> cap_;
  std::vector<Point> points_, hull_;
  std::vector<Open> open_, next_;
  std::size_t rects_capacity_ = 0;
};

} // namespace camhead::renderer::region_geometry
