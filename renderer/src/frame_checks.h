// What both frame renderers refuse (frame_renderer.h), worded alike, and how
// both read a plate-only request.
#pragma once

#include <cstddef>
#include <string>

#include "camhead/base/video_format.h"
#include "camhead/renderer/frame_renderer.h"

namespace camhead::renderer {

// Why a frame of `format` (`bytes` long) cannot be a plate or an output of a
// width x height render, or empty.
[[nodiscard]] inline std::string check_frame(const base::VideoFormat &format, std::size_t bytes,
                                             int width, int height) {
  if (std::string reason = base::check_video_format(format); !reason.empty())
    return reason;
  if (format.width != width || format.height != height)
    return base::describe(format) + " is not the render size " + std::to_string(width) + "x" +
           std::to_string(height);
  if (bytes < base::frame_bytes(format))
    return base::describe(format) + " needs " + std::to_string(base::frame_bytes(format)) +
           " bytes, not " + std::to_string(bytes);
  return {};
}

// The first problem with a frame's plate and outputs, or empty.
[[nodiscard]] inline std::string
check_frames(const VideoFrame &plate, std::span<const VideoBuffer> outputs, int width, int height) {
  if (!plate.bytes.empty())
    if (std::string reason = check_frame(plate.format, plate.bytes.size(), width, height);
        !reason.empty())
      return "camera frame: " + reason;
  for (const VideoBuffer &out : outputs)
    if (std::string reason = check_frame(out.format, out.bytes.size(), width, height);
        !reason.empty())
      return "output: " + reason;
  return {};
}

// The first problem with what `request` asks of a frame with or without a
// camera frame, or empty.
[[nodiscard]] inline std::string check_request(const FrameRequest &request, bool has_plate) {
  if (request.rays_per_pixel == 0)
    return "0 rays per pixel";
  if (!(request.extra_rays_per_pixel >= 0.0f && request.extra_rays_per_pixel < 1.0f))
    return "a fraction of a ray a pixel of " + std::to_string(request.extra_rays_per_pixel) +
           ", not in [0, 1)";
  if (request.accumulation.enabled && request.adaptive)
    return "adaptive frames do not accumulate";
  if (request.accumulation.enabled && request.accumulation.max_samples == 0)
    return "a history of at most 0 samples";
  if (request.plate_only && !has_plate)
    return "a plate-only frame without a camera frame";
  return {};
}

// The same pixels in the same bytes, whatever the rows' padding: an output
// in the camera frame's own format, which outside the influence region takes
// the camera's bytes as they are.
[[nodiscard]] inline bool same_pixels(base::VideoFormat a, base::VideoFormat b) {
  a.stride = b.stride = 0;
  return a == b;
}

// `request` as the executors render it: a plate-only frame traces
// nothing, so it neither accumulates nor samples adaptively (and the
// history before it ends, as after any frame that does not accumulate).
[[nodiscard]] inline FrameRequest as_rendered(const FrameRequest &request) {
  FrameRequest rendered = request;
  if (request.plate_only) {
    rendered.accumulation.enabled = false;
    rendered.adaptive = false;
  }
  return rendered;
}

[[nodiscard]] inline FrameReport bad_frame(std::string detail) {
  FrameReport report;
  report.status = FrameStatus::bad_input;
  report.detail = std::move(detail);
  return report;
}

} // namespace camhead::renderer
