// A linear-light float image, the one pixel container of the renderer.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>

namespace camhead::renderer {

// Row-major, row 0 at the top, `channels` floats per pixel (1 or 3).
struct Image {
  int width = 0;
  int height = 0;
  int channels = 3;
  std::vector<float> data;

  Image() = default;
  Image(int w, int h, int c)
      : width(w), height(h), channels(c), data(std::size_t(w) * h * c, 0.0f) {}

  [[nodiscard]] std::size_t pixel_count() const { return std::size_t(width) * height; }
  [[nodiscard]] float *at(int x, int y) { return &data[(std::size_t(y) * width + x) * channels]; }
  [[nodiscard]] const float *at(int x, int y) const {
    return &data[(std::size_t(y) * width + x) * channels];
  }
};

} // namespace camhead::renderer
