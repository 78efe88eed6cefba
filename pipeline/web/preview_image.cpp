#include "preview_image.h"

#include <algorithm>
#include <cmath>

namespace camhead::pipeline::web {
namespace {

using base::PixelFormat;

// Sums of Y', Cb, Cr (or R', G', B') over a box of pixels.
struct Sum {
  std::uint32_t a = 0, b = 0, c = 0;
};

// Y'CbCr of the matrix and range to R'G'B' in [0, 255] (BT.601-7, BT.709-6),
// from the means of a box.
struct YcbcrToRgb {
  float y_offset, y_scale, c_scale;
  float cr_to_r, cb_to_g, cr_to_g, cb_to_b;

  explicit YcbcrToRgb(const base::VideoFormat &format) {
    const bool bt601 = format.matrix == base::ColorMatrix::bt601;
    const float kr = bt601 ? 0.299f : 0.2126f, kb = bt601 ? 0.114f : 0.0722f;
    const bool limited = format.range == base::ColorRange::limited;
    y_offset = limited ? 16.0f : 0.0f;
    y_scale = limited ? 255.0f / 219.0f : 1.0f;
    c_scale = limited ? 255.0f / 224.0f : 1.0f;
    cr_to_r = 2.0f * (1.0f - kr);
    cb_to_b = 2.0f * (1.0f - kb);
    const float kg = 1.0f - kr - kb;
    cb_to_g = -kb * cb_to_b / kg;
    cr_to_g = -kr * cr_to_r / kg;
  }

  void operator()(float y, float cb, float cr, std::uint8_t *rgb) const {
    const float l = (y - y_offset) * y_scale;
    const float u = (cb - 128.0f) * c_scale, v = (cr - 128.0f) * c_scale;
    const auto byte = [](float x) { return std::uint8_t(std::clamp(std::lround(x), 0L, 255L)); };
    rgb[0] = byte(l + cr_to_r * v);
    rgb[1] = byte(l + cb_to_g * u + cr_to_g * v);
    rgb[2] = byte(l + cb_to_b * u);
  }
};

} // namespace

int preview_factor(int width) {
  return std::max(1, (width + kPreviewMaxWidth - 1) / kPreviewMaxWidth);
}

PreviewImage preview_for(const base::VideoFormat &format) {
  const int factor = preview_factor(format.width);
  // Even sizes: a 4:2:x frame's chroma pairs never straddle two preview pixels.
  const int step = base::is_yuv(format.pixel) ? std::max(2, factor + factor % 2) : factor;
  PreviewImage image;
  image.width = std::max(1, format.width / step);
  image.height = std::max(1, format.height / step);
  image.rgb.assign(std::size_t(image.width) * std::size_t(image.height) * 3, 0);
  return image;
}

void shrink_to_preview(const base::VideoFormat &format, std::span<const std::uint8_t> frame,
                       PreviewImage &out) {
  const std::size_t stride = base::row_bytes(format);
  const int step_x = format.width / out.width, step_y = format.height / out.height;
  const std::uint32_t count = std::uint32_t(step_x * step_y);
  const YcbcrToRgb to_rgb(format);
  const std::uint8_t *rows = frame.data();
  // NV12's chroma plane follows the luma plane, with the same stride.
  const std::uint8_t *chroma = rows + stride * std::size_t(format.height);
  for (int py = 0; py < out.height; ++py) {
    for (int px = 0; px < out.width; ++px) {
      Sum sum;
      for (int dy = 0; dy < step_y; ++dy) {
        const int y = py * step_y + dy;
        const std::uint8_t *row = rows + stride * std::size_t(y);
        for (int dx = 0; dx < step_x; ++dx) {
          const int x = px * step_x + dx;
          switch (format.pixel) {
          case PixelFormat::yuyv: {
            const std::uint8_t *pair = row + std::size_t(x / 2) * 4;
            sum.a += row[std::size_t(x) * 2];
            sum.b += pair[1];
            sum.c += pair[3];
            break;
          }
          case PixelFormat::nv12: {
            const std::uint8_t *c = chroma + stride * std::size_t(y / 2) + std::size_t(x / 2) * 2;
            sum.a += row[x];
            sum.b += c[0];
            sum.c += c[1];
            break;
          }
          case PixelFormat::rgb24:
          case PixelFormat::bgr24: {
            const std::uint8_t *p = row + std::size_t(x) * 3;
            const bool bgr = format.pixel == PixelFormat::bgr24;
            sum.a += p[bgr ? 2 : 0];
            sum.b += p[1];
            sum.c += p[bgr ? 0 : 2];
            break;
          }
          case PixelFormat::xrgb8888: {
            const std::uint8_t *p = row + std::size_t(x) * 4; // B G R X
            sum.a += p[2];
            sum.b += p[1];
            sum.c += p[0];
            break;
          }
          }
        }
      }
      std::uint8_t *rgb = out.rgb.data() + (std::size_t(py) * std::size_t(out.width) + px) * 3;
      if (base::is_yuv(format.pixel)) {
        to_rgb(float(sum.a) / float(count), float(sum.b) / float(count),
               float(sum.c) / float(count), rgb);
      } else {
        rgb[0] = std::uint8_t((sum.a + count / 2) / count);
        rgb[1] = std::uint8_t((sum.b + count / 2) / count);
        rgb[2] = std::uint8_t((sum.c + count / 2) / count);
      }
    }
  }
  out.valid = true;
}

} // namespace camhead::pipeline::web
