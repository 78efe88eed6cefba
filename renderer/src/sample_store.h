// The last frames' camera samples, kept so that a frame after a lens change
// starts with them rather than with nothing (a focus pull at the
// camera's rate; Lehtinen et al. 2011 reproject samples the same way).
//
// While the pose holds, a thin-lens sample is one ray of the world: it left
// the entrance pupil at `a` (metres along the camera's right and up) with
// slope `t` (its right and up per unit along the view). A camera of image
// scale f (pixels) focused at F sees that ray at
//
//     x = w / 2 + f (t.x + a.x / F),    y = h / 2 - f (t.y + a.y / F)
//
// (kernel.glsl, camera_ray, solved for the pixel), so a new focus, image
// scale or smaller aperture moves each sample to the pixel whose ray it is,
// exactly, occlusion, shadows and all: what it brought back is what that
// pixel's ray would bring back. Nothing is interpolated and nothing of the
// old focus remains.
//
// Samples are unbiased for a pixel only if they cover its whole new
// aperture as uniformly as a fresh render would. The map from (old pixel,
// pupil point) to (new pixel, pupil point) is linear with a constant
// determinant, so the samples of a frame that traced every pixel of its
// region alike stay uniform wherever they land; a new pixel takes them only
// if every ray of its new aperture comes from a pixel the old frame traced
// (its rays' pixels bounded by a box), and a pixel takes only the samples
// inside its new aperture (a frame whose aperture was smaller than the new
// one is not used). A different pose, image, pixel filter, light count,
// world colour, bounce count or lens model (its distortion, principal point
// and fy / fx; the image scale may breathe) makes a frame unusable.
//
// Through a lens model (renderer/shaders/lens_model.glsl) the pixel is the
// lens's image of the focal-plane point t + a / F on the ideal image plane,
// which is just as exact for where a sample lands. The map from old to new
// pixels is then no longer linear: a sample's density within its new pixel
// varies by as much as the lens's stretch changes over the distance the
// sample moved (a blur radius's change; for a lens of k1 = -0.3, under 1 %
// for a move of 10 pixels), a bias far below the noise it replaces. Which
// old pixels a new one draws on is bounded on the ideal plane and taken
// through the lens with a margin for its bending (covers_through_lens).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec4.hpp>

#include "camhead/renderer/accumulation.h"
#include "camhead/renderer/frame_settings.h"
#include "camhead/renderer/gpu_layout.h"
#include "camhead/renderer/influence_region.h"
#include "lens_model_math.h"

namespace camhead::renderer::cpu {

// One camera sample: its ray as the pose sees it, and what it brought back.
struct StoredSample {
  glm::vec4 ray;   // slope t (right, up), pupil point a (right, up; m)
  glm::vec4 mixed; // mixed radiance, and 1 where the ray hit a virtual object
  glm::vec4 real;  // real radiance, and the hit's depth (negative: no hit)
};

// Whether cameras `a` and `b` see the same rays: the same pose, image,
// pixel filter, light count, world colour, bounce count and lens model (the
// thin lens aside).
[[nodiscard]] bool same_view(const gpu::FrameParams &a, const gpu::FrameParams &b);

// Whether samples of a frame of camera `from` can be moved into one of
// camera `to` (the header comment: the same pose and everything else that
// shapes a sample, an aperture no smaller, a 1-pixel box filter).
[[nodiscard]] bool reprojectable(const gpu::FrameParams &from, const gpu::FrameParams &to);

class SampleStore {
public:
  static constexpr std::size_t kMostFrames = AccumulationSettings::kMostReprojectFrames;

  // Room for `capacity` samples of frames of width x height pixels. Nothing
  // is allocated after this.
  void reserve(std::size_t capacity, std::uint32_t width, std::uint32_t height);
  [[nodiscard]] bool reserved() const { return !samples_.empty(); }
  void clear();

  // Room for the `count` samples of a frame of camera `camera` that traced
  // every pixel of `region` alike, to be filled by the caller; the oldest
  // frames make way. Empty if they would not fit at all.
  [[nodiscard]] std::span<StoredSample> add_frame(const gpu::FrameParams &camera,
                                                  const InfluenceRegion &region, std::size_t count);

  // Moving samples into a frame of camera `to`, in two steps: begin()
  // chooses the newest `most` frames usable by `to` and, for the pixels of
  // `region`, where each covers the whole new aperture; rows() then calls
  // add(pixel, sample) for each of their samples that lands on such a pixel
  // in rows [y0, y1) (pixel = y * width + x), in the order stored, so that
  // the sums are the same from run to run, and returns how many. Calls of
  // rows() for disjoint rows may run at once.
  void begin_reprojection(const gpu::FrameParams &to, const InfluenceRegion &region,
                          std::size_t most);
  template <typename Add>
  std::uint64_t reproject_rows(std::uint32_t y0, std::uint32_t y1, Add &&add) const;

private:
  struct Frame {
    gpu::FrameParams camera{};
    std::size_t first = 0, count = 0; // in samples_
    // Its region's rectangles, in the order of its samples (row by row in
    // each), and its samples per pixel.
    std::vector<PixelRect> rects;
    std::uint32_t per_pixel = 0;
    // Summed-area table of the region's tiles, (tiles_x + 1) x (tiles_y + 1).
    std::vector<std::uint32_t> traced_tiles;
  };

  // Whether `frame` traced every pixel in [x0, x1] x [y0, y1] (inclusive).
  [[nodiscard]] bool traced(const Frame &frame, int x0, int y0, int x1, int y1) const;

  // Where the pixels [x0, x1) x [y0, y1) of a camera of image scale f and
  // focus 1 / w_to with an aperture A_to take the rays that `frame` saw:
  //   x_from - w/2 = s (x - w/2) - f_from a (w_to - w_from),  s = f_from / f,
  // for every pupil point |a| <= A_to, within r = f_from A_to |w_to - w_from|
  // of the scaled pixels; true if `frame` traced all of them.
  // Through a lens model the same by the box's centre alone (one inverse
  // and one image of the lens): the box's preimage lies within its
  // half-diagonal over the lens's least stretch of the centre's preimage
  // (`per_px`: ideal-plane units per pixel, a tenth more for the stretch's
  // change across the box), grown by `move` = A_to |w_to - w_from|, and
  // that in `frame` within the most it stretches (`stretch`) times as much.
  struct Preimage {
    double s, r, half_w, half_h;
    double move = 0.0, per_px = 0.0, stretch = 1.0; // with a lens model
  };
  [[nodiscard]] bool covers(const Frame &frame, const Preimage &p, std::uint32_t x0,
                            std::uint32_t y0, std::uint32_t x1, std::uint32_t y1) const {
    if (has_lens_model(to_))
      return covers_through_lens(frame, p, x0, y0, x1, y1);
    const double lo_x = p.half_w + p.s * (double(x0) - p.half_w) - p.r;
    const double hi_x = p.half_w + p.s * (double(x1) - p.half_w) + p.r;
    const double lo_y = p.half_h + p.s * (double(y0) - p.half_h) - p.r;
    const double hi_y = p.half_h + p.s * (double(y1) - p.half_h) + p.r;
    return traced(frame, int(std::floor(lo_x)), int(std::floor(lo_y)), int(std::ceil(hi_x)) - 1,
                  int(std::ceil(hi_y)) - 1);
  }
  [[nodiscard]] bool covers_through_lens(const Frame &frame, const Preimage &p, std::uint32_t x0,
                                         std::uint32_t y0, std::uint32_t x1,
                                         std::uint32_t y1) const;

  // A frame chosen by begin_reprojection(), and for each tile of the new
  // frame: kOutside (not in its region), kCovered (every pixel covered) or
  // kEdge (some may not be: each is checked).
  static constexpr std::uint8_t kOutside = 0, kCovered = 1, kEdge = 2;
  struct Source {
    const Frame *frame = nullptr;
    Preimage preimage{};
    std::uint32_t reach = 0; // rows: how far a sample may move up or down
    std::vector<std::uint8_t> tiles;
  };

  std::vector<StoredSample> samples_;
  std::array<Frame, kMostFrames> frames_;
  std::size_t newest_ = 0, stored_ = 0; // a ring: frames_[newest_] is the newest
  std::uint32_t width_ = 0, height_ = 0, tiles_x_ = 0, tiles_y_ = 0;
  std::array<Source, kMostFrames> sources_;
  std::size_t source_count_ = 0;
  gpu::FrameParams to_{}; // the camera the sources move into
  // Through a lens model, the most it moves a row from the pinhole's (one
  // pixel more for the floats).
  float row_shift_ = 0.0f;
};

template <typename Add>
std::uint64_t SampleStore::reproject_rows(std::uint32_t y0, std::uint32_t y1, Add &&add) const {
  std::uint64_t given = 0;
  const float half_w = 0.5f * float(to_.image.x);
  const float half_h = 0.5f * float(to_.image.y);
  const float f = to_.lens.z;
  const float inv_focus = 1.0f / to_.lens.y;
  const float aperture2 = to_.lens.x * to_.lens.x;
  const bool lens = has_lens_model(to_);
  const float fy = to_.lens.z * to_.projection.z;
  for (std::size_t k = 0; k < source_count_; ++k) {
    const Source &source = sources_[k];
    const Frame &frame = *source.frame;
    // Only the rows whose samples can land in [y0, y1) are read.
    const std::uint32_t first_row = y0 > source.reach ? y0 - source.reach : 0;
    const std::uint32_t end_row = y1 + source.reach;
    std::size_t rect_first = frame.first;
    for (const PixelRect &rect : frame.rects) {
      const std::size_t row_samples = std::size_t(rect.x1 - rect.x0) * frame.per_pixel;
      const std::size_t first_of_rect = rect_first;
      rect_first += row_samples * (rect.y1 - rect.y0);
      const std::uint32_t row0 = std::max(rect.y0, first_row), row1 = std::min(rect.y1, end_row);
      if (row0 >= row1)
        continue;
      const std::size_t end = first_of_rect + row_samples * (row1 - rect.y0);
      for (std::size_t s = first_of_rect + row_samples * (row0 - rect.y0); s < end; ++s) {
        const StoredSample &sample = samples_[s];
        const glm::vec4 &r = sample.ray;
        float px, py;
        if (lens) {
          // Where the sample meets the focal plane, through the lens; first
          // whether the lens can move it into these rows at all (two
          // multiplications, where the lens takes a few dozen).
          const float ideal_y = -(r.y + r.w * inv_focus);
          const float row = to_.projection.y + fy * ideal_y;
          if (!(row >= float(y0) - row_shift_ && row < float(y1) + row_shift_))
            continue;
          const glm::vec2 d = LensModelMath{}.lens_distort({r.x + r.z * inv_focus, ideal_y},
                                                           to_.distortion, to_.projection.w);
          px = to_.projection.x + f * d.x;
          py = to_.projection.y + f * to_.projection.z * d.y;
        } else {
          px = half_w + f * (r.x + r.z * inv_focus);
          py = half_h - f * (r.y + r.w * inv_focus);
        }
        if (!(py >= float(y0) && py < float(y1)) || r.z * r.z + r.w * r.w > aperture2)
          continue; // another's rows, or outside the new aperture
        if (!(px >= 0.0f && px < float(width_)))
          continue;
        const std::uint32_t x = std::uint32_t(px);
        const std::uint32_t y = std::uint32_t(py);
        const std::uint8_t tile =
            source.tiles[std::size_t(y / CAMHEAD_TILE_Y) * tiles_x_ + x / CAMHEAD_TILE_X];
        if (tile == kOutside ||
            (tile == kEdge && !covers(frame, source.preimage, x, y, x + 1, y + 1)))
          continue;
        add(std::size_t(y) * width_ + x, sample);
        ++given;
      }
    }
  }
  return given;
}

} // namespace camhead::renderer::cpu
