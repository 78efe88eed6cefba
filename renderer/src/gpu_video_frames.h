// Camera and output frames on their way to and from the GPU's video
// kernels (video_decode.comp, video_encode.comp): the formats' codes and
// parameters, and the rows copied between the frames' strides and the
// kernels' packed rows.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include <vulkan/vulkan.h>

#include "camhead/base/video_format.h"
#include "camhead/renderer/gpu_layout.h"
#include "camhead/renderer/influence_region.h"

namespace camhead::renderer {

// The largest frame of any format: 4 bytes per pixel (xrgb8888).
[[nodiscard]] VkDeviceSize max_video_bytes(std::size_t pixels);

// The kernels' code for a pixel format (layout.h, VIDEO_*).
[[nodiscard]] std::uint32_t video_format_code(base::PixelFormat pixel);

// A frame as the video kernels see it: packed rows starting at `first_word`.
[[nodiscard]] gpu::VideoParams video_params(const base::VideoFormat &f, std::uint32_t first_word);

// Rows of `height` (plus NV12's chroma rows) between two strides.
void copy_rows(const std::uint8_t *from, std::size_t from_stride, std::uint8_t *to,
               std::size_t to_stride, const base::VideoFormat &f);

// The bytes of `rects` alone, as copy_rows copies all of them. The rects are
// whole tiles (influence_region.h): even rows and columns, so no 4:2:2 pixel
// pair or 4:2:0 chroma sample straddles an edge.
void copy_rects(const std::uint8_t *from, std::size_t from_stride, std::uint8_t *to,
                std::size_t to_stride, const base::VideoFormat &f,
                std::span<const PixelRect> rects);

} // namespace camhead::renderer
