// The renderer as the live pipeline drives it: one scene loaded once, then a
// frame at a time, each with its own camera (pose and lens at mid-exposure)
// and its own plate (the camera frame in the camera's own pixel format), and
// the composite written straight into each output's buffer in that output's
// format. The scene, the kernels and the per-pixel buffers are made when the
// renderer is created, the GPU's pipelines by prepare(), and nothing is
// thrown per frame: what goes wrong is the returned status. Nor is anything
// allocated per frame once prepared, on either executor, held shot or focus
// pull (tests/renderer/frame_allocations_test.cpp, which says what it
// counts), except an adaptive frame's shares on the CPU reference.
//
// Thread safety: one thread renders at a time.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include <glm/vec4.hpp>

#include "camhead/base/video_format.h"
#include "camhead/renderer/accumulation.h"
#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/frame_budget.h"
#include "camhead/renderer/frame_camera.h"
#include "camhead/renderer/scene.h"

namespace camhead::renderer {

// A camera frame as it arrived, or an output buffer to fill.
struct VideoFrame {
  base::VideoFormat format;
  std::span<const std::uint8_t> bytes;
};
struct VideoBuffer {
  base::VideoFormat format;
  std::span<std::uint8_t> bytes;
};

struct FrameRequest {
  FrameCamera camera;
  std::uint32_t rays_per_pixel = 1; // the mean, for adaptive frames
  // A fraction of a ray a pixel more, on average, in [0, 1): the part of a
  // frame budget between two whole numbers (frame_budget.h). Only frames
  // that share their rays unevenly spend it: the CPU reference's
  // accumulating frames with share_by_noise, a history's first frame with
  // nothing moved into it (its sharp pixels first, then whole blocks of its
  // blurred ones) and a held shot's after the pilot (its noisiest pixels;
  // ray_shares.h). The others trace rays_per_pixel.
  float extra_rays_per_pixel = 0.0f;
  bool adaptive = false;
  AdaptiveSampling adaptive_settings;
  // The frame's own noise pattern; 0 takes the scene's render.seed. An
  // accumulating frame that continues a history keeps the history's.
  std::uint32_t seed = 0;
  // Add this frame's `rays_per_pixel` samples to those of the frames before
  // while the camera stays within the tolerance (frame_history.h); not with
  // `adaptive`. The GPU executor gives every pixel of the region the same
  // samples: it does not share them by noise, nor move them through a new
  // lens, yet.
  AccumulationSettings accumulation;
  // Trace only where the virtual objects can change the composite
  // (influence_region.h); the outputs are the same bit for bit, except for
  // accumulating frames that share rays by noise or reconstruct (both look
  // at the traced pixels only: accumulation.h). False traces every pixel,
  // for comparison.
  bool influence_region = true;
  // The composite is the camera frame alone, as a frame outside the
  // influence region is, bit for bit: nothing is traced, and an
  // accumulating history ends. For a frame whose camera pose is not known
  // yet, where virtual objects drawn from a guess would be worse than none.
  // Needs a camera frame.
  bool plate_only = false;
  // For measurement (camhead bench live): keep the frame's float composite
  // for last_composite() on an executor that otherwise leaves it on the
  // device. The GPU's then resolves every pixel and reads the composite
  // back, a copy of the whole layer and allocations each frame; the outputs
  // get the bytes they would get without it. On the GPU a change of it
  // starts a new history.
  bool keep_composite = false;
};

// Sets `request`'s rays per pixel to `mean` (at least 1; NaN is 1) rounded
// down to sixteenths of a ray (kRaySteps, frame_budget.h): its whole part
// in rays_per_pixel, the rest in extra_rays_per_pixel.
inline void set_mean_rays_per_pixel(FrameRequest &request, double mean) {
  const double at_least_one = mean >= 1.0 ? mean : 1.0;
  const double sixteenths = in_ray_steps(at_least_one);
  request.rays_per_pixel = std::uint32_t(sixteenths);
  request.extra_rays_per_pixel = float(sixteenths - std::floor(sixteenths));
}

enum class FrameStatus {
  ok,
  bad_input,   // a plate or output that does not fit the renderer (`detail` says how)
  device_lost, // the GPU is gone: the renderer renders nothing more
};

struct FrameReport {
  FrameStatus status = FrameStatus::ok;
  std::string detail;
  std::uint64_t camera_rays = 0;
  // Pixels traced (the influence region's) of the frame's, and the region
  // itself (influence_region.h; every pixel when the request traces
  // without one), valid until the renderer's next render().
  std::uint64_t traced_pixels = 0;
  std::span<const PixelRect> region;
  std::uint64_t frame_pixels = 0;
  // Accumulating frames: the samples per pixel the image holds (the mean
  // over the region), and whether this frame started a new history (the
  // camera moved, or the one before did not accumulate).
  std::uint32_t history_samples = 0;
  bool history_restarted = false;
  // Samples a new history took from the frames before, moved through the
  // new lens (accumulation.h, reproject); counted in history_samples.
  std::uint64_t reprojected_samples = 0;
  // Where the frame's time went, seconds: converting the plate in, tracing
  // (and the reconstruction; on the GPU the compositing too), compositing
  // and converting the composite out.
  double decode_s = 0.0;
  double trace_s = 0.0;
  double encode_s = 0.0;
  // Of trace_s, the samples' pass (their shares and tracing them): what
  // grows with the rays per pixel (frame_budget.h). 0 where the renderer
  // does not tell it apart (the GPU executor, whose device time is one
  // figure).
  double rays_s = 0.0;
};

class FrameRenderer {
public:
  virtual ~FrameRenderer() = default;
  FrameRenderer() = default;
  FrameRenderer(const FrameRenderer &) = delete;
  FrameRenderer &operator=(const FrameRenderer &) = delete;

  // "cpu reference, 2 threads", "gpu NVIDIA H100 80GB HBM3", for status lines.
  [[nodiscard]] virtual std::string executor() const = 0;

  // Renders one frame: `plate` is the camera image I_c (same size as the
  // scene's render size), each of `outputs` gets the composite I_f in its
  // own format (same size). The scene's own plate is not used; a plate
  // without bytes is none, and the outputs get I_m (the scene as rendered).
  [[nodiscard]] virtual FrameReport render(const FrameRequest &request, const VideoFrame &plate,
                                           std::span<const VideoBuffer> outputs) = 0;

  // Builds, before the first frame, what frames like `request` with a
  // camera frame of `plate` (none: frames without) and outputs of `outputs`
  // need: the GPU's pipelines, the influence region's world-space part. So
  // no frame compiles, and none allocates from the first
  // (tests/renderer/frame_allocations_test.cpp). Without it the first frames
  // do this work. Throws what the constructor throws, and
  // std::invalid_argument for more outputs than render() takes.
  virtual void prepare(const FrameRequest &request, const std::optional<base::VideoFormat> &plate,
                       std::span<const base::VideoFormat> outputs) = 0;

  // The last frame's composite in linear RGB (alpha unused), row by row, for
  // measurement before the outputs' 8-bit rounding: set over the frame's
  // influence region only. Empty on an executor that keeps it on the device,
  // unless the frame asked for it (FrameRequest::keep_composite).
  [[nodiscard]] virtual std::span<const glm::vec4> last_composite() const { return {}; }
};

// The CPU reference tracer (cpu_tracer.h) as a frame renderer, on `threads`
// threads (<= 0: one per hardware thread), kept for its lifetime. Throws
// std::invalid_argument for a scene whose render size is not a video size.
[[nodiscard]] std::unique_ptr<FrameRenderer> make_cpu_frame_renderer(const Scene &scene,
                                                                     int threads = 0);

// The GPU tracer (gpu_tracer.h) as a frame renderer on `device` (as
// GpuTracer's constructor takes it), the conversions on the device too.
// Throws GpuError, or std::invalid_argument for a render width that is not
// a multiple of 4 or an odd height.
[[nodiscard]] std::unique_ptr<FrameRenderer>
make_gpu_frame_renderer(const Scene &scene, const std::string &device = {});

} // namespace camhead::renderer
