#include "preview_image.h"

#include <algorithm>
#include <array>

namespace camhead::pipeline::web {
namespace {

using base::PixelFormat;

// Sums over the boxes of one row of preview pixels: Y', Cb, Cr (or R',
// G', B') of each box. On the stack: a preview is at most kPreviewMaxWidth
// wide.
struct RowSums {
  std::array<std::uint32_t, kPreviewMaxWidth> a, b, c;
};

// Y'CbCr of the matrix and range to R'G'B' in [0, 255] (BT.601-7, BT.709-6),
// from a box's sums.
struct YcbcrToRgb {
  float y_offset, y_scale, c_scale;
  float cr_to_r, cb_to_g, cr_to_g, cb_to_b;

  YcbcrToRgb(const base::VideoFormat &format, std::uint32_t count) {
    const bool bt601 = format.matrix == base::ColorMatrix::bt601;
    const float kr = bt601 ? 0.299f : 0.2126f, kb = bt601 ? 0.114f : 0.0722f;
    const bool limited = format.range == base::ColorRange::limited;
    const float mean = 1.0f / float(count);
    y_offset = limited ? 16.0f : 0.0f;
    y_scale = (limited ? 255.0f / 219.0f : 1.0f) * mean;
    c_scale = (limited ? 255.0f / 224.0f : 1.0f) * mean;
    y_offset *= float(count) * y_scale; // subtracted from the scaled sum
    cr_to_r = 2.0f * (1.0f - kr);
    cb_to_b = 2.0f * (1.0f - kb);
    const float kg = 1.0f - kr - kb;
    cb_to_g = -kb * cb_to_b / kg;
    cr_to_g = -kr * cr_to_r / kg;
    chroma_sum_offset = 128.0f * float(count);
  }

  void operator()(std::uint32_t y, std::uint32_t cb, std::uint32_t cr, std::uint8_t *rgb) const {
    const float l = float(y) * y_scale - y_offset;
    const float u = (float(cb) - chroma_sum_offset) * c_scale;
    const float v = (float(cr) - chroma_sum_offset) * c_scale;
    rgb[0] = byte(l + cr_to_r * v);
    rgb[1] = byte(l + cb_to_g * u + cr_to_g * v);
    rgb[2] = byte(l + cb_to_b * u);
  }

  static std::uint8_t byte(float x) { return std::uint8_t(std::clamp(x, 0.0f, 255.0f) + 0.5f); }

  float chroma_sum_offset;
};

// Adds one frame row to the sums: `step` frame pixels to a box, `width`
// boxes. YUYV: a pair's two pixels share their Cb and Cr, and a box (an
// even number of pixels wide) holds whole pairs.
void add_yuyv_row(const std::uint8_t *row, int step, int width, RowSums &s) {
  const std::uint8_t *p = row;
  for (int o = 0; o < width; ++o) {
    std::uint32_t a = 0, b = 0, c = 0;
    for (int k = 0; k < step; k += 2, p += 4) {
      a += std::uint32_t(p[0]) + p[2];
      b += p[1];
      c += p[3];
    }
    s.a[std::size_t(o)] += a;
    s.b[std::size_t(o)] += 2 * b;
    s.c[std::size_t(o)] += 2 * c;
  }
}

// NV12: a luma row and the chroma row it shares with its neighbour.
void add_nv12_row(const std::uint8_t *luma, const std::uint8_t *chroma, int step, int width,
                  RowSums &s) {
  for (int o = 0; o < width; ++o) {
    std::uint32_t a = 0, b = 0, c = 0;
    for (int k = 0; k < step; k += 2, luma += 2, chroma += 2) {
      a += std::uint32_t(luma[0]) + luma[1];
      b += chroma[0];
      c += chroma[1];
    }
    s.a[std::size_t(o)] += a;
    s.b[std::size_t(o)] += 2 * b;
    s.c[std::size_t(o)] += 2 * c;
  }
}

// Packed R'G'B' of `bytes` a pixel, the three channels at offsets r, g, b.
void add_rgb_row(const std::uint8_t *row, int step, int width, int bytes, int r, int g, int b,
                 RowSums &s) {
  const std::uint8_t *p = row;
  for (int o = 0; o < width; ++o) {
    std::uint32_t sr = 0, sg = 0, sb = 0;
    for (int k = 0; k < step; ++k, p += bytes) {
      sr += p[r];
      sg += p[g];
      sb += p[b];
    }
    s.a[std::size_t(o)] += sr;
    s.b[std::size_t(o)] += sg;
    s.c[std::size_t(o)] += sb;
  }
}

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
  const YcbcrToRgb to_rgb(format, count);
  const std::uint8_t *rows = frame.data();
  // NV12's chroma plane follows the luma plane, with the same stride.
  const std::uint8_t *chroma = rows + stride * std::size_t(format.height);
  RowSums sums;
  for (int py = 0; py < out.height; ++py) {
    std::fill_n(sums.a.begin(), out.width, 0u);
    std::fill_n(sums.b.begin(), out.width, 0u);
    std::fill_n(sums.c.begin(), out.width, 0u);
    for (int y = py * step_y; y < (py + 1) * step_y; ++y) {
      const std::uint8_t *row = rows + stride * std::size_t(y);
      switch (format.pixel) {
      case PixelFormat::yuyv:
        add_yuyv_row(row, step_x, out.width, sums);
        break;
      case PixelFormat::nv12:
        add_nv12_row(row, chroma + stride * std::size_t(y / 2), step_x, out.width, sums);
        break;
      case PixelFormat::rgb24:
        add_rgb_row(row, step_x, out.width, 3, 0, 1, 2, sums);
        break;
      case PixelFormat::bgr24:
        add_rgb_row(row, step_x, out.width, 3, 2, 1, 0, sums);
        break;
      case PixelFormat::xrgb8888: // B G R X bytes
        add_rgb_row(row, step_x, out.width, 4, 2, 1, 0, sums);
        break;
      }
    }
    std::uint8_t *rgb = out.rgb.data() + std::size_t(py) * std::size_t(out.width) * 3;
    if (base::is_yuv(format.pixel)) {
      for (int px = 0; px < out.width; ++px, rgb += 3)
        to_rgb(sums.a[std::size_t(px)], sums.b[std::size_t(px)], sums.c[std::size_t(px)], rgb);
    } else {
      for (int px = 0; px < out.width; ++px, rgb += 3) {
        rgb[0] = std::uint8_t((sums.a[std::size_t(px)] + count / 2) / count);
        rgb[1] = std::uint8_t((sums.b[std::size_t(px)] + count / 2) / count);
        rgb[2] = std::uint8_t((sums.c[std::size_t(px)] + count / 2) / count);
      }
    }
  }
  out.valid = true;
}

void shade_outside(std::span<const renderer::PixelRect> region, int frame_width, int frame_height,
                   PreviewImage &preview) {
  const int step_x = frame_width / preview.width, step_y = frame_height / preview.height;
  // The first preview pixel of a `step` wide box whose centre is at or past
  // frame pixel `at`.
  const auto first_from = [](std::uint32_t at, int step) {
    const std::uint32_t half = std::uint32_t(step / 2);
    return at <= half ? 0 : int((at - half + std::uint32_t(step) - 1) / std::uint32_t(step));
  };
  std::array<bool, kPreviewMaxWidth> inside;
  for (int py = 0; py < preview.height; ++py) {
    const std::uint32_t y = std::uint32_t(py * step_y + step_y / 2);
    std::fill_n(inside.begin(), preview.width, false);
    for (const renderer::PixelRect &r : region)
      if (r.y0 <= y && y < r.y1)
        std::fill(inside.begin() + std::min(first_from(r.x0, step_x), preview.width),
                  inside.begin() + std::min(first_from(r.x1, step_x), preview.width), true);
    std::uint8_t *rgb = preview.rgb.data() + std::size_t(py) * std::size_t(preview.width) * 3;
    for (int px = 0; px < preview.width; ++px, rgb += 3)
      if (!inside[std::size_t(px)])
        for (int c = 0; c < 3; ++c)
          rgb[c] = std::uint8_t(rgb[c] / 3);
  }
}

} // namespace camhead::pipeline::web
