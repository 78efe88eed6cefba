// The GPU tracer as a live frame renderer (frame_renderer.h): the camera
// frame's conversion, the trace and the outputs' conversion all on the
// device, one submission for a steady frame (GpuTracer::render_video).
#include <algorithm>
#include <array>
#include <optional>
#include <stdexcept>
#include <string>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/influence_region.h"
#include "frame_checks.h"
#include "vulkan_context.h"

namespace camhead::renderer {
namespace {

class GpuFrameRenderer final : public FrameRenderer {
public:
  GpuFrameRenderer(const Scene &scene, const std::string &device)
      : scene_(without_plate(scene)), compiled_(compile_scene(scene_)), tracer_(device) {
    const int w = scene_.render.width;
    const int h = scene_.render.height;
    if (w <= 0 || h <= 0 || w % 4 != 0 || h % 2 != 0)
      throw std::invalid_argument(scene.source.string() + ": render: size " + std::to_string(w) +
                                  "x" + std::to_string(h) +
                                  " is not one the GPU video kernels take (width a multiple of "
                                  "4, even height)");
    tracer_.load(compiled_);
  }

  std::string executor() const override { return "gpu " + tracer_.device_name(); }

  void prepare(const FrameRequest &request, const std::optional<base::VideoFormat> &plate,
               std::span<const base::VideoFormat> outputs) override {
    if (outputs.size() > VIDEO_MAX_OUTPUTS)
      throw std::invalid_argument(std::to_string(outputs.size()) +
                                  " outputs; the GPU executor takes " +
                                  std::to_string(VIDEO_MAX_OUTPUTS));
    const gpu::FrameParams frame = frame_params(request, plate.has_value());
    if (request.influence_region)
      static_cast<void>(regions_.build(frame));
    std::array<base::PixelFormat, VIDEO_MAX_OUTPUTS> pixels{};
    for (std::size_t k = 0; k < outputs.size(); ++k)
      pixels[k] = outputs[k].pixel;
    tracer_.prepare_video(frame,
                          plate ? std::optional<base::PixelFormat>(plate->pixel) : std::nullopt,
                          std::span(pixels.data(), outputs.size()), request.adaptive);
  }

  FrameReport render(const FrameRequest &request, const VideoFrame &plate,
                     std::span<const VideoBuffer> outputs) override {
    if (lost_)
      return lost("the GPU was lost earlier");
    if (std::string reason =
            check_frames(plate, outputs, scene_.render.width, scene_.render.height);
        !reason.empty())
      return bad_frame(std::move(reason));
    if (outputs.size() > VIDEO_MAX_OUTPUTS)
      return bad_frame(std::to_string(outputs.size()) + " outputs; the GPU executor takes " +
                       std::to_string(VIDEO_MAX_OUTPUTS));
    if (request.rays_per_pixel == 0)
      return bad_frame("0 rays per pixel");
    if (request.accumulation.enabled && request.adaptive)
      return bad_frame("adaptive frames do not accumulate");
    const gpu::FrameParams frame = frame_params(request, !plate.bytes.empty());
    FrameReport report;
    try {
      const InfluenceRegion &region = request.influence_region
                                          ? regions_.build(frame)
                                          : regions_.whole_frame(frame.image.x, frame.image.y);
      report.traced_pixels = region.pixels();
      report.frame_pixels = std::uint64_t(frame.image.x) * frame.image.y;
      const RenderResult result = tracer_.render_video(
          frame, plate, outputs, request.adaptive ? &request.adaptive_settings : nullptr, &region);
      report.camera_rays = result.camera_rays;
      // No history on this executor yet: an accumulating frame starts one
      // and ends it, which is what the report says.
      if (request.accumulation.enabled) {
        report.history_samples = request.rays_per_pixel;
        report.history_restarted = true;
      }
      // The conversions run on the device inside the frame's one
      // submission: their time is part of the trace time here.
      report.trace_s = result.timings.device_s > 0.0 ? result.timings.device_s : result.seconds;
      report.encode_s = result.timings.unpack_s; // the outputs' copy out of mapped memory
    } catch (const vk::VulkanError &e) {
      if (e.result() == VK_ERROR_DEVICE_LOST) {
        lost_ = true;
        return lost(e.what());
      }
      return bad_frame(e.what());
    } catch (const std::exception &e) {
      return bad_frame(e.what());
    }
    return report;
  }

private:
  gpu::FrameParams frame_params(const FrameRequest &request, bool has_plate) const {
    gpu::FrameParams frame =
        make_frame_params(scene_, request.camera, int(std::max(request.rays_per_pixel, 1u)));
    if (request.seed != 0)
      frame.sampling.w = request.seed;
    frame.image.z = has_plate ? 1u : 0u; // the camera frame is the plate
    return frame;
  }

  static Scene without_plate(Scene scene) {
    scene.plate.reset();
    return scene;
  }

  static FrameReport lost(std::string detail) {
    FrameReport report;
    report.status = FrameStatus::device_lost;
    report.detail = std::move(detail);
    return report;
  }

  Scene scene_;
  CompiledScene compiled_; // for each frame's influence region
  GpuTracer tracer_;
  InfluenceRegionBuilder regions_{compiled_};
  bool lost_ = false;
};

} // namespace

std::unique_ptr<FrameRenderer> make_gpu_frame_renderer(const Scene &scene,
                                                       const std::string &device) {
  return std::make_unique<GpuFrameRenderer>(scene, device);
}

} // namespace camhead::renderer
