// The GPU tracer as a live frame renderer (frame_renderer.h): the camera
// frame's conversion, the trace and the outputs' conversion all on the
// device, one submission for a steady frame (GpuTracer::render_video). A
// held shot accumulates in the device's accumulators (frame_history.h):
// every pixel of the region the next samples of one Sobol' pattern, and the
// reconstruction on the device too (reconstruct.glsl); the shares by noise
// and the samples moved through a new lens are the CPU reference's alone so
// far.
#include <algorithm>
#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/frame_history.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/influence_region.h"
#include "defocus_filter.h"
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
    history_valid_ = false; // the region it traced is no longer in regions_
    std::array<base::PixelFormat, VIDEO_MAX_OUTPUTS> pixels{};
    for (std::size_t k = 0; k < outputs.size(); ++k)
      pixels[k] = outputs[k].pixel;
    tracer_.prepare_video(frame,
                          plate ? std::optional<base::PixelFormat>(plate->pixel) : std::nullopt,
                          std::span(pixels.data(), outputs.size()), request.adaptive);
  }

  FrameReport render(const FrameRequest &asked, const VideoFrame &plate,
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
    if (std::string reason = check_request(asked, !plate.bytes.empty()); !reason.empty())
      return bad_frame(std::move(reason));
    const FrameRequest request = as_rendered(asked);
    gpu::FrameParams frame = frame_params(request, !plate.bytes.empty());
    const Shape shape = shape_of(plate, outputs, request);
    std::optional<GpuTracer::SampleRange> samples;
    const bool continues = request.accumulation.enabled && continues_history(request, frame, shape);
    FrameReport report;
    if (request.accumulation.enabled) {
      if (continues) {
        // Its camera and seed, so that the samples stay one pattern's; the
        // reconstruction is the frame's own.
        const gpu::vec4 reconstruct = frame.reconstruct;
        frame = history_;
        frame.reconstruct = reconstruct;
      } else {
        history_ = frame;
        history_shape_ = shape;
        history_valid_ = true;
        history_samples_ = 0;
      }
      const std::uint32_t end =
          std::min(history_samples_ + request.rays_per_pixel, frame.sampling.z);
      samples = GpuTracer::SampleRange{history_samples_, end};
      history_samples_ = end;
      report.history_samples = end;
      report.history_restarted = !continues;
    } else {
      history_valid_ = false;
    }
    try {
      if (!continues) // a history keeps the region of its start (frame_history.h)
        region_ = request.plate_only         ? &regions_.none(frame.image.x, frame.image.y)
                  : request.influence_region ? &regions_.build(frame)
                                             : &regions_.whole_frame(frame.image.x, frame.image.y);
      report.traced_pixels = region_->pixels();
      report.region = region_->rects;
      report.frame_pixels = std::uint64_t(frame.image.x) * frame.image.y;
      const RenderResult result = tracer_.render_video(
          frame, plate, outputs, request.adaptive ? &request.adaptive_settings : nullptr, region_,
          samples, request.keep_composite);
      if (request.keep_composite) {
        composite_.resize(result.composite.pixel_count());
        for (std::size_t i = 0; i < composite_.size(); ++i)
          composite_[i] = glm::vec4(result.composite.data[3 * i], result.composite.data[3 * i + 1],
                                    result.composite.data[3 * i + 2], 0.0f);
      } else {
        composite_.clear();
      }
      report.camera_rays = result.camera_rays;
      // The conversions run on the device inside the frame's one
      // submission: their time is part of the trace time here.
      report.trace_s = result.timings.device_s > 0.0 ? result.timings.device_s : result.seconds;
      report.encode_s = result.timings.unpack_s; // the outputs' copy out of mapped memory
    } catch (const vk::VulkanError &e) {
      history_valid_ = false;
      if (e.result() == VK_ERROR_DEVICE_LOST) {
        lost_ = true;
        return lost(e.what());
      }
      return bad_frame(e.what());
    } catch (const std::exception &e) {
      history_valid_ = false;
      return bad_frame(e.what());
    }
    return report;
  }

  std::span<const glm::vec4> last_composite() const override { return composite_; }

private:
  gpu::FrameParams frame_params(const FrameRequest &request, bool has_plate) const {
    gpu::FrameParams frame =
        make_frame_params(scene_, request.camera, int(std::max(request.rays_per_pixel, 1u)));
    if (request.seed != 0)
      frame.sampling.w = request.seed;
    frame.image.z = has_plate ? 1u : 0u; // the camera frame is the plate
    if (request.accumulation.enabled) {
      // One pattern of the history's greatest size, its samples taken in
      // order, every sample traced on its own. Owen-scrambled Sobol', as the
      // CPU reference's: progressive, so that every prefix is an evenly
      // spread estimate (a prefix of one CMJ pattern is unbiased but hardly
      // stratified: at the rig's far and scene focus, after 50 frames it had
      // 1.6-1.9 times the error of 49 fresh CMJ rays; bench/RESULTS.md, "The
      // GPU executor reconstructs; its history in Sobol'").
      frame.tracing.z = SAMPLER_SOBOL;
      frame.sampling.z = std::max(request.accumulation.max_samples, 1u);
      frame.tracing.w &= ~TRACING_SKIP_EMPTY_PIXELS;
      if (request.accumulation.reconstruct && request.accumulation.reconstruct_strength > 0.0) {
        const cpu::DefocusFilterSettings filter; // the CPU reference's reach and least sigma
        frame.reconstruct =
            gpu::vec4(float(request.accumulation.reconstruct_strength), float(filter.min_sigma_px),
                      float(filter.max_radius_px), 0.0f);
      }
    }
    return frame;
  }

  // What a history's frames must share besides the camera: the kinds of
  // frames in and out, whether the region or every pixel is traced, and
  // whether the composite comes back (the accumulators outside a region are
  // cleared only where a frame reads them, which depends on the outputs'
  // formats and on that: GpuTracer::render_video).
  struct Shape {
    bool plate = false;
    base::PixelFormat plate_pixel = base::PixelFormat::yuyv;
    std::size_t outputs = 0;
    std::array<base::PixelFormat, VIDEO_MAX_OUTPUTS> output_pixels{};
    bool influence_region = true;
    bool keep_composite = false;
    bool operator==(const Shape &) const = default;
  };

  static Shape shape_of(const VideoFrame &plate, std::span<const VideoBuffer> outputs,
                        const FrameRequest &request) {
    Shape shape;
    shape.plate = !plate.bytes.empty();
    shape.plate_pixel = plate.format.pixel;
    shape.outputs = outputs.size();
    for (std::size_t k = 0; k < outputs.size(); ++k)
      shape.output_pixels[k] = outputs[k].format.pixel;
    shape.influence_region = request.influence_region;
    shape.keep_composite = request.keep_composite;
    return shape;
  }

  // Whether `frame` may add to the history: the one before accumulated, with
  // the same settings and shape, and the camera moved less than the
  // tolerance (frame_history.h).
  bool continues_history(const FrameRequest &request, const gpu::FrameParams &frame,
                         const Shape &shape) const {
    if (!history_valid_ || frame.sampling.z != history_.sampling.z || !(shape == history_shape_))
      return false;
    const double change = frame_change_px(history_, frame, nearest_depth_m(compiled_, history_));
    return change <= request.accumulation.tolerance_px;
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
  const InfluenceRegion *region_ = nullptr; // this frame's, in regions_
  // The history: the accumulators' camera and pattern, and what they hold.
  gpu::FrameParams history_{};
  Shape history_shape_;
  bool history_valid_ = false;
  std::uint32_t history_samples_ = 0; // every pixel of the region alike
  bool lost_ = false;
  std::vector<glm::vec4> composite_; // the last frame's, where it asked (keep_composite)
};

} // namespace

std::unique_ptr<FrameRenderer> make_gpu_frame_renderer(const Scene &scene,
                                                       const std::string &device) {
  return std::make_unique<GpuFrameRenderer>(scene, device);
}

} // namespace camhead::renderer
