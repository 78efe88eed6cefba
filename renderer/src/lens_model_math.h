// renderer/shaders/lens_model.glsl for the C++ side: the same source, inside
// a struct as cpu_kernel.h includes kernel.glsl, so that the host's
// projections (frame_settings.cpp, region_geometry.h) and the kernels agree
// to the last bit of float arithmetic.
#pragma once

#include <cmath>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace camhead::renderer::cpu {

struct LensModelMath {
  static float sqrt(float v) { return std::sqrt(v); }
  using vec2 = glm::vec2;
  using vec3 = glm::vec3;
  using vec4 = glm::vec4;
#include "lens_model.glsl"
};

} // namespace camhead::renderer::cpu
