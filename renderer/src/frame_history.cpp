#include "camhead/renderer/frame_history.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/frame_settings.h"

namespace camhead::renderer {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

glm::dvec3 xyz(const gpu::vec4 &v) {
  return {v.x, v.y, v.z};
}

// Blur-circle radius, pixels, of a point at inverse depth w (1/m): a point
// at depth z is seen by the pixels within f A |1/z - 1/F| of its pinhole
// projection (influence_region.cpp, step 2).
double blur_radius_px(const gpu::FrameParams &f, double w) {
  return double(f.lens.x) * double(f.lens.z) * std::abs(w - 1.0 / double(f.lens.y));
}

} // namespace

double nearest_depth_m(const CompiledScene &scene, const gpu::FrameParams &frame) {
  if (scene.nodes.empty())
    return kNearestDepthM;
  const gpu::BvhNode &root = scene.nodes.front();
  const glm::dvec3 lo = xyz(root.bmin);
  const glm::dvec3 hi = xyz(root.bmax);
  if (!(std::abs(lo.x) < 1e30)) // the empty BVH: nothing to see
    return kNearestDepthM;
  const glm::dvec3 pupil = xyz(frame.cam_position) - glm::dvec3(scene.origin);
  const glm::dvec3 forward = xyz(frame.cam_forward);
  double nearest = kInfinity;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 p((corner & 1) != 0 ? hi.x : lo.x, (corner & 2) != 0 ? hi.y : lo.y,
                       (corner & 4) != 0 ? hi.z : lo.z);
    nearest = std::min(nearest, glm::dot(p - pupil, forward));
  }
  return std::max(nearest, kNearestDepthM);
}

double frame_change_px(const gpu::FrameParams &a, const gpu::FrameParams &b, double nearest_m) {
  // What no tolerance covers: what is not the camera.
  if (a.lens.w != b.lens.w || a.world_color != b.world_color || a.image != b.image ||
      a.tracing.x != b.tracing.x || has_lens_model(a) != has_lens_model(b) ||
      (has_lens_model(a) && (a.projection != b.projection || a.distortion != b.distortion)))
    return kInfinity;
  for (const gpu::FrameParams *frame : {&a, &b})
    for (int k = 0; k < 4; ++k)
      if (!std::isfinite(frame->lens[k]) || !std::isfinite(frame->cam_position[k]) ||
          !std::isfinite(frame->cam_right[k]) || !std::isfinite(frame->cam_up[k]) ||
          !std::isfinite(frame->cam_forward[k]))
        return kInfinity; // no bound to give
  const double f = a.lens.z;
  const double w_far = 0.0;
  const double w_near = 1.0 / nearest_m;
  // The largest blur radius of either frame: a point that far outside the
  // picture still reaches its edge.
  double widest = 0.0;
  for (const gpu::FrameParams *frame : {&a, &b})
    for (const double w : {w_far, w_near})
      widest = std::max(widest, blur_radius_px(*frame, w));
  // The farthest a visible point lies from the image centre, as a tangent
  // (through a lens model, its preimage's), and the most the lens model
  // stretches a motion on the ideal image plane (1 for a pinhole).
  const LensExtent extent = lens_extent(a, (widest + a.lens.w) / f);
  const double max_tan = extent.max_tan + (widest + a.lens.w) / f;
  // 1. Position. A point at depth z >= nearest seen at u = f x / z moves by
  //    (f / z)(|dx| + max_tan |dz|) <= |dp| (f + f max_tan) / nearest when
  //    the pupil moves by dp (the entrance pupil follows focus and zoom),
  //    and by |df| max_tan when the image scale f breathes.
  const double moved = glm::length(xyz(b.cam_position) - xyz(a.cam_position));
  double change = moved * f * (1.0 + max_tan) / nearest_m;
  change += std::abs(double(b.lens.z) - f) * max_tan;
  // 2. Blur. At one depth, the difference of the two radii is piecewise
  //    linear in w = 1/z over [0, 1/nearest], with kinks at the focal
  //    planes: its largest magnitude is at an end or a kink.
  double blur = 0.0;
  for (const double w : {w_far, w_near, 1.0 / double(a.lens.y), 1.0 / double(b.lens.y)})
    if (w >= w_far && w <= w_near)
      blur = std::max(blur, std::abs(blur_radius_px(b, w) - blur_radius_px(a, w)));
  change += blur;
  // ... and the pupil moving along the view changes every depth, so every
  // 1/z by up to |dp| / nearest^2, and a radius by A f times that.
  const double aperture = std::max(double(a.lens.x), double(b.lens.x));
  change += moved * f * aperture / (nearest_m * nearest_m);
  // 3. Turning (a tracked pose that jitters). The two views' axes differ by
  //    a rotation of angle theta, |B_b - B_a| = 2 sqrt(2) sin(theta / 2)
  //    (Frobenius). A point at tan phi from the axis moves by at most
  //    f theta (1 + tan^2 phi) (a pan or tilt: d tan / d phi; a roll moves
  //    it by f theta tan phi, less), and its depth along the view by up to
  //    z theta tan phi, which changes its blur radius by f A theta tan phi / z.
  const double turned2 =
      glm::dot(xyz(b.cam_right) - xyz(a.cam_right), xyz(b.cam_right) - xyz(a.cam_right)) +
      glm::dot(xyz(b.cam_up) - xyz(a.cam_up), xyz(b.cam_up) - xyz(a.cam_up)) +
      glm::dot(xyz(b.cam_forward) - xyz(a.cam_forward), xyz(b.cam_forward) - xyz(a.cam_forward));
  const double theta = 2.0 * std::asin(std::min(1.0, std::sqrt(turned2 / 8.0)));
  change += f * theta * (1.0 + max_tan * max_tan);
  change += f * aperture * theta * max_tan / nearest_m;
  change *= extent.stretch;
  return std::isfinite(change) ? change : kInfinity;
}

} // namespace camhead::renderer
