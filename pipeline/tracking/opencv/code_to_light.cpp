#include "code_to_light.h"

#include <cstdint>

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

// The renderer's conversions themselves (as renderer/src/video_codec.cpp
// includes them), in this module's own namespace.
namespace camhead::pipeline::video_glsl {
using namespace glm; // the GLSL built-ins video.glsl calls unqualified
using uint = std::uint32_t;
#include "video.glsl"
} // namespace camhead::pipeline::video_glsl

namespace camhead::pipeline {
namespace glsl = video_glsl;

cv::Mat light_table(bool limited_range, int depth) {
  cv::Mat table(1, 256, CV_32F);
  for (int code = 0; code < 256; ++code) {
    const float y =
        glsl::video_normalise_ycbcr(glm::vec3(float(code), 128.0f, 128.0f),
                                    limited_range ? VIDEO_RANGE_LIMITED : VIDEO_RANGE_FULL)
            .x;
    table.at<float>(code) = 255.0f * glsl::srgb_decode(y);
  }
  if (depth == CV_32F)
    return table;
  cv::Mat rounded;
  table.convertTo(rounded, depth); // saturated: the foot- and headroom clipped
  return rounded;
}

} // namespace camhead::pipeline
