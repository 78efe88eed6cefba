// The camera of one live frame as a plain value: where the camera is and what
// the physical lens is doing at that frame's mid-exposure. pipeline/ fills it
// from the pose and lens_control's LensState; a scene file's camera is its
// default (scene_camera()).
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/scene.h"

namespace camhead::renderer {

// The real lens beyond a centred pinhole of square pixels, in OpenCV's
// terms (renderer/shaders/lens_model.glsl): the principal point as a
// fraction of the image's width and height from its top-left corner, the
// focal length down the image over the one across it (fy / fx), and
// Brown-Conrady distortion. The defaults are the ideal lens, which renders
// as a pinhole camera always has.
struct LensModel {
  glm::vec2 principal_point{0.5f, 0.5f};
  float fy_over_fx = 1.0f;
  float k1 = 0.0f, k2 = 0.0f, k3 = 0.0f, p1 = 0.0f, p2 = 0.0f;

  [[nodiscard]] bool ideal() const {
    return principal_point == glm::vec2(0.5f) && fy_over_fx == 1.0f && k1 == 0.0f && k2 == 0.0f &&
           k3 == 0.0f && p1 == 0.0f && p2 == 0.0f;
  }
};

struct FrameCamera {
  // The pose: the lens's reference plane (where the lens profile measures the
  // entrance pupil from), the point it looks at and the up direction, world
  // metres.
  glm::vec3 position{0.0f};
  glm::vec3 look_at{0.0f, 0.0f, -1.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  // Metres from the entrance pupil to the focal plane; +infinity allowed.
  float focus_distance_m = 0.0f;
  // 0 = pinhole.
  float f_number = 0.0f;
  // The lens's focal length: with the f-number it sets the aperture,
  // f / (2 N) in radius.
  float focal_length_mm = 35.0f;
  // The focal length that reproduces the image scale (focus breathing); it
  // sets the field of view. 0 = focal_length_mm.
  float projection_focal_length_mm = 0.0f;
  float sensor_width_mm = 36.0f;
  // The entrance pupil, metres in front of `position` along the view axis:
  // where the lens rays start and the focus distance is measured from.
  float entrance_pupil_offset_m = 0.0f;
  // The principal point and distortion; the image scale across the image is
  // the projection focal length's.
  LensModel lens_model;
};

// What stops make_frame_params() from building a camera frame, in the
// float32 it works in (it would divide by zero, and the frame render
// nothing): `no_direction`, `look_at` too close to `position` for the view
// (or too far: float squares overflow) for the view to have a direction;
// `no_orientation`, `up` parallel to the view (within 1e-6 of the unit
// vectors' cross product, the scene format's rule), zero, or too short or
// too long to give the picture a direction. The scene reader and the board
// reader both refuse such a camera.
enum class ViewProblem { none, no_direction, no_orientation };
[[nodiscard]] ViewProblem view_problem(glm::vec3 position, glm::vec3 look_at, glm::vec3 up);

// The scene file's camera: pupil at its position, no breathing.
[[nodiscard]] FrameCamera scene_camera(const Scene &scene);

} // namespace camhead::renderer
