// A frame's renderer camera from the pose and the lens state at its
// mid-exposure: pipeline's translation between lens_control and renderer.
#pragma once

#include "camhead/lens_control/lens_state.h"
#include "camhead/renderer/frame_camera.h"

namespace camhead::pipeline {

// `base` supplies the pose and the sensor width; the lens state everything
// the lens decides.
[[nodiscard]] inline renderer::FrameCamera lens_camera(renderer::FrameCamera base,
                                                       const lens_control::LensState &lens) {
  base.focus_distance_m = float(lens.focus_distance_m.value);
  base.f_number = float(lens.f_number.value);
  base.focal_length_mm = float(lens.focal_length_mm.value);
  base.projection_focal_length_mm = float(lens.projection_focal_length_mm.value);
  base.entrance_pupil_offset_m = float(lens.entrance_pupil_offset_mm.value / 1000.0);
  return base;
}

} // namespace camhead::pipeline
