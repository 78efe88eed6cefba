#include "video_codec.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace camhead::renderer::video {
namespace {

float fast_srgb_decode(float v);
float fast_srgb_encode(float v);

namespace glsl {
using namespace glm; // the GLSL built-ins video.glsl calls unqualified
using uint = std::uint32_t;
#define VIDEO_SRGB_DECODE fast_srgb_decode
#define VIDEO_SRGB_ENCODE fast_srgb_encode
#include "video.glsl"
#undef VIDEO_SRGB_DECODE
#undef VIDEO_SRGB_ENCODE
} // namespace glsl

// The sRGB curve in tables, linear between entries: pow costs about 20 ns
// a channel, three a pixel each way (7 and 9 ms of a 720x576 frame on two
// cores). Within [-1, 1] (every in-gamut code, and most that are not) the
// tables are within 1e-6 of glsl::srgb_decode / srgb_encode; outside, the
// functions themselves. The encode table is indexed by sqrt(x), where the
// 1/2.4 power is smooth enough for a linear step (h^2/8 |f''| < 4e-8).
class SrgbTables {
public:
  static constexpr int kSteps = 4096;

  SrgbTables() {
    for (int i = 0; i <= kSteps; ++i) {
      const float t = float(i) / kSteps;
      decode_[i] = glsl::srgb_decode(t);
      encode_[i] = glsl::srgb_encode(t * t);
    }
  }

  [[nodiscard]] float decode(float v) const {
    const float a = std::fabs(v);
    if (!(a <= 1.0f)) // also NaN
      return glsl::srgb_decode(v);
    const float lin = lerp(decode_, a);
    return v < 0.0f ? -lin : lin;
  }

  [[nodiscard]] float encode(float v) const {
    const float a = std::fabs(v);
    if (!(a <= 1.0f))
      return glsl::srgb_encode(v);
    // The linear segment exactly, as the function has it.
    const float enc = a <= 0.0031308f ? 12.92f * a : lerp(encode_, std::sqrt(a));
    return v < 0.0f ? -enc : enc;
  }

private:
  static float lerp(const std::array<float, kSteps + 1> &table, float t) {
    const float x = t * kSteps;
    const int i = std::min(int(x), kSteps - 1);
    const float f = x - float(i);
    return table[std::size_t(i)] + f * (table[std::size_t(i) + 1] - table[std::size_t(i)]);
  }

  std::array<float, kSteps + 1> decode_{};
  std::array<float, kSteps + 1> encode_{};
};

const SrgbTables &srgb_tables() {
  static const SrgbTables tables;
  return tables;
}

float fast_srgb_decode(float v) {
  return srgb_tables().decode(v);
}

float fast_srgb_encode(float v) {
  return srgb_tables().encode(v);
}

using base::PixelFormat;

glm::uint matrix_of(const base::VideoFormat &f) {
  return f.matrix == base::ColorMatrix::bt601 ? VIDEO_MATRIX_BT601 : VIDEO_MATRIX_BT709;
}

glm::uint range_of(const base::VideoFormat &f) {
  return f.range == base::ColorRange::full ? VIDEO_RANGE_FULL : VIDEO_RANGE_LIMITED;
}

glm::vec3 ycbcr_to_linear(const base::VideoFormat &f, std::uint8_t y, std::uint8_t cb,
                          std::uint8_t cr) {
  const glm::vec3 ypbpr = glsl::video_normalise_ycbcr(glm::vec3(y, cb, cr), range_of(f));
  return glsl::video_ypbpr_to_linear(ypbpr, matrix_of(f));
}

std::uint8_t code(float value) {
  return static_cast<std::uint8_t>(glsl::video_round_code(value));
}

} // namespace

void decode_row(const base::VideoFormat &f, std::span<const std::uint8_t> frame, int y,
                glm::vec4 *out, int x0, int x1) {
  const int end = x1 < 0 ? f.width : x1;
  const std::size_t stride = base::row_bytes(f);
  const std::uint8_t *row = frame.data() + stride * std::size_t(y);
  switch (f.pixel) {
  case PixelFormat::yuyv:
    for (int x = x0; x < end; x += 2) {
      const std::uint8_t *p = row + 2 * std::size_t(x);
      out[x] = glm::vec4(ycbcr_to_linear(f, p[0], p[1], p[3]), 0.0f);
      out[x + 1] = glm::vec4(ycbcr_to_linear(f, p[2], p[1], p[3]), 0.0f);
    }
    break;
  case PixelFormat::nv12: {
    const std::uint8_t *chroma =
        frame.data() + stride * std::size_t(f.height) + stride * std::size_t(y / 2);
    for (int x = x0; x < end; ++x) {
      const std::size_t c = 2 * std::size_t(x / 2);
      out[x] = glm::vec4(ycbcr_to_linear(f, row[x], chroma[c], chroma[c + 1]), 0.0f);
    }
    break;
  }
  case PixelFormat::rgb24:
  case PixelFormat::bgr24: {
    const bool bgr = f.pixel == PixelFormat::bgr24;
    for (int x = x0; x < end; ++x) {
      const std::uint8_t *p = row + 3 * std::size_t(x);
      const glm::vec3 codes = bgr ? glm::vec3(p[2], p[1], p[0]) : glm::vec3(p[0], p[1], p[2]);
      out[x] = glm::vec4(glsl::video_rgb_codes_to_linear(codes), 0.0f);
    }
    break;
  }
  case PixelFormat::xrgb8888:
    for (int x = x0; x < end; ++x) {
      const std::uint8_t *p = row + 4 * std::size_t(x); // B G R X in memory
      out[x] = glm::vec4(glsl::video_rgb_codes_to_linear(glm::vec3(p[2], p[1], p[0])), 0.0f);
    }
    break;
  }
}

void encode_rows(const base::VideoFormat &f, std::span<std::uint8_t> frame, const glm::vec4 *image,
                 int y0, int y1, int x0, int x1) {
  const int end = x1 < 0 ? f.width : x1;
  const std::size_t stride = base::row_bytes(f);
  const std::size_t width = std::size_t(f.width);
  const auto pixel = [&](int x, int y) { return glm::vec3(image[std::size_t(y) * width + x]); };
  const auto ypbpr = [&](int x, int y) {
    return glsl::video_linear_to_ypbpr(pixel(x, y), matrix_of(f));
  };
  const auto codes = [&](glm::vec3 v) { return glsl::video_code_ycbcr(v, range_of(f)); };
  switch (f.pixel) {
  case PixelFormat::yuyv:
    for (int y = y0; y < y1; ++y) {
      std::uint8_t *row = frame.data() + stride * std::size_t(y);
      for (int x = x0; x < end; x += 2) {
        const glm::vec3 a = ypbpr(x, y);
        const glm::vec3 b = ypbpr(x + 1, y);
        const glm::vec3 ca = codes(a);
        const glm::vec3 cb = codes(b);
        const glm::vec3 chroma = codes(glm::vec3(0.0f, 0.5f * (a.y + b.y), 0.5f * (a.z + b.z)));
        std::uint8_t *p = row + 2 * std::size_t(x);
        p[0] = code(ca.x);
        p[1] = code(chroma.y);
        p[2] = code(cb.x);
        p[3] = code(chroma.z);
      }
    }
    break;
  case PixelFormat::nv12:
    for (int y = y0; y < y1; y += 2) {
      std::uint8_t *luma0 = frame.data() + stride * std::size_t(y);
      std::uint8_t *luma1 = luma0 + stride;
      std::uint8_t *chroma =
          frame.data() + stride * std::size_t(f.height) + stride * std::size_t(y / 2);
      for (int x = x0; x < end; x += 2) {
        glm::vec3 sum(0.0f);
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            const glm::vec3 v = ypbpr(x + dx, y + dy);
            (dy == 0 ? luma0 : luma1)[x + dx] = code(codes(v).x);
            sum += v;
          }
        const glm::vec3 c = codes(glm::vec3(0.0f, 0.25f * sum.y, 0.25f * sum.z));
        chroma[x] = code(c.y);
        chroma[x + 1] = code(c.z);
      }
    }
    break;
  case PixelFormat::rgb24:
  case PixelFormat::bgr24: {
    const bool bgr = f.pixel == PixelFormat::bgr24;
    for (int y = y0; y < y1; ++y) {
      std::uint8_t *row = frame.data() + stride * std::size_t(y);
      for (int x = x0; x < end; ++x) {
        const glm::vec3 c = glsl::video_linear_to_rgb_codes(pixel(x, y));
        std::uint8_t *p = row + 3 * std::size_t(x);
        p[bgr ? 2 : 0] = code(c.x);
        p[1] = code(c.y);
        p[bgr ? 0 : 2] = code(c.z);
      }
    }
    break;
  }
  case PixelFormat::xrgb8888:
    for (int y = y0; y < y1; ++y) {
      std::uint8_t *row = frame.data() + stride * std::size_t(y);
      for (int x = x0; x < end; ++x) {
        const glm::vec3 c = glsl::video_linear_to_rgb_codes(pixel(x, y));
        std::uint8_t *p = row + 4 * std::size_t(x);
        p[0] = code(c.z);
        p[1] = code(c.y);
        p[2] = code(c.x);
        p[3] = 0xff;
      }
    }
    break;
  }
}

void copy_row(const base::VideoFormat &from_format, std::span<const std::uint8_t> from,
              const base::VideoFormat &to_format, std::span<std::uint8_t> to, int row) {
  std::memcpy(to.data() + base::row_bytes(to_format) * std::size_t(row),
              from.data() + base::row_bytes(from_format) * std::size_t(row),
              base::packed_stride(from_format.pixel, from_format.width));
}

} // namespace camhead::renderer::video
