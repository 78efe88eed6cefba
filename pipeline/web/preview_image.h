// The operator page's preview of a video frame: the frame shrunk by a whole
// factor (a box filter, so a preview pixel is the mean of the frame's) and
// turned into 8-bit R'G'B' with the frame's own matrix and range, the bytes
// a JPEG encoder takes. Made on the page's thread from the copy the frame
// loop hands it (web_feed.h), into storage made once.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "camhead/base/video_format.h"
#include "camhead/renderer/influence_region.h"

namespace camhead::pipeline::web {

// Previews are at most this wide (and as tall as the frame's aspect gives):
// a phone's screen, and a JPEG a few tens of kilobytes.
inline constexpr int kPreviewMaxWidth = 640;

struct PreviewImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb; // width * height * 3 bytes, rows top down
  std::uint64_t frame = 0;       // the composite's output frame, or the camera frame's sequence
  bool valid = false;            // false until a frame was shrunk into it
};

// How many frame pixels a preview pixel spans each way, for a frame `width` wide.
[[nodiscard]] int preview_factor(int width);
// An image sized for `format`'s previews (its pixels allocated here).
[[nodiscard]] PreviewImage preview_for(const base::VideoFormat &format);

// Shrinks `frame` (laid out as `format`) into `out`, made by preview_for()
// for the same format; allocates nothing.
void shrink_to_preview(const base::VideoFormat &format, std::span<const std::uint8_t> frame,
                       PreviewImage &out);

// The region view: darkens to a third each pixel of `preview` (shrunk from
// a frame_width x frame_height frame) whose box's centre lies outside
// `region`, the frame's traced pixels (FrameReport::region), so that what
// the tracer worked on stands out; allocates nothing.
void shade_outside(std::span<const renderer::PixelRect> region, int frame_width, int frame_height,
                   PreviewImage &preview);

} // namespace camhead::pipeline::web
