// A frame's renderer camera from the pose and the lens state at its
// mid-exposure: pipeline's translation between lens_control and renderer.
#pragma once

#include "camhead/lens_control/lens_state.h"
#include "camhead/renderer/frame_camera.h"

namespace camhead::pipeline {

// The lens's principal point, pixel shape and distortion, as the renderer
// takes them.
[[nodiscard]] inline renderer::LensModel lens_model(const lens_control::LensState &lens) {
  renderer::LensModel model;
  model.principal_point = {float(lens.projection.principal_x), float(lens.projection.principal_y)};
  model.fy_over_fx = float(lens.projection.fy_over_fx);
  if (const auto &d = lens.distortion) {
    model.k1 = float(d->k1);
    model.k2 = float(d->k2);
    model.k3 = float(d->k3);
    model.p1 = float(d->p1);
    model.p2 = float(d->p2);
  }
  return model;
}

// `base` supplies the pose and the sensor width; the lens state everything
// the lens decides.
[[nodiscard]] inline renderer::FrameCamera lens_camera(renderer::FrameCamera base,
                                                       const lens_control::LensState &lens) {
  base.focus_distance_m = float(lens.focus_distance_m.value);
  base.f_number = float(lens.f_number.value);
  base.focal_length_mm = float(lens.focal_length_mm.value);
  base.projection_focal_length_mm = float(lens.projection_focal_length_mm.value);
  base.entrance_pupil_offset_m = float(lens.entrance_pupil_offset_mm.value / 1000.0);
  base.lens_model = lens_model(lens);
  return base;
}

} // namespace camhead::pipeline
