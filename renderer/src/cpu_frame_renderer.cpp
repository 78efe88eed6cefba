// The CPU reference as a live frame renderer (frame_renderer.h): the scene
// compiled and the kernel bound once, the per-pixel buffers and the threads
// made once, then per frame four passes over the rows: the camera frame into
// the linear plate, the samples (a pilot and a second pass when adaptive),
// and the resolve with each output's encoding.
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/frame_renderer.h"
#include "cpu_kernel.h"
#include "frame_checks.h"
#include "video_codec.h"
#include "worker_pool.h"

namespace camhead::renderer {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

class CpuFrameRenderer final : public FrameRenderer {
public:
  CpuFrameRenderer(const Scene &scene, int threads)
      : scene_(without_plate(scene)), compiled_(compile_scene(scene_)), pool_(threads),
        pixels_(std::size_t(scene_.render.width) * std::size_t(scene_.render.height)),
        plate_(pixels_), composite_(pixels_), mixed_(pixels_), real_(pixels_), aux_(pixels_) {
    const int w = scene_.render.width;
    const int h = scene_.render.height;
    if (w <= 0 || h <= 0 || w % 2 != 0 || h % 2 != 0)
      throw std::invalid_argument(scene.source.string() + ": render: size " + std::to_string(w) +
                                  "x" + std::to_string(h) +
                                  " is not a video frame size (even width and height)");
    kernel_ = cpu::make_cpu_kernel(compiled_, make_frame_params(scene_), nodes_);
  }

  std::string executor() const override {
    return "cpu reference, " + std::to_string(pool_.threads()) + " thread" +
           (pool_.threads() == 1 ? "" : "s");
  }

  FrameReport render(const FrameRequest &request, const VideoFrame &plate,
                     std::span<const VideoBuffer> outputs) override {
    FrameReport report;
    const int width = scene_.render.width;
    const int height = scene_.render.height;
    const bool has_plate = !plate.bytes.empty();
    if (std::string reason = check_frames(plate, outputs, width, height); !reason.empty())
      return bad_frame(std::move(reason));
    if (request.rays_per_pixel == 0)
      return bad_frame("0 rays per pixel");

    gpu::FrameParams frame = make_frame_params(scene_, request.camera, int(request.rays_per_pixel));
    frame.image.z = has_plate ? 1u : 0u; // the camera frame is the plate
    if (request.seed != 0)
      frame.sampling.w = request.seed;
    cpu::set_cpu_frame(kernel_, compiled_, frame);

    Clock::time_point start = Clock::now();
    auto decode = [&](int y) {
      video::decode_row(plate.format, plate.bytes, y, &plate_[std::size_t(y) * width]);
    };
    if (has_plate)
      pool_.run(height, decode);
    report.decode_s = seconds_since(start);

    start = Clock::now();
    const std::uint32_t total = frame.sampling.z;
    if (!request.adaptive) {
      trace(0u, total, true, has_plate);
      report.camera_rays = std::uint64_t(pixels_) * total;
    } else {
      const std::uint32_t pilot = adaptive_pilot(request.adaptive_settings, total);
      kernel_.frame.sampling = gpu::uvec4(0u, pilot, pilot, frame.sampling.w);
      trace(0u, pilot, true, has_plate);
      // allocate_samples() returns a new vector: the one allocation a live
      // frame makes, adaptive frames only.
      counts_ = allocate_samples(aux_, frame, pilot, request.adaptive_settings);
      const std::uint32_t most = *std::max_element(counts_.begin(), counts_.end());
      kernel_.sample_counts = counts_.data();
      kernel_.frame.tracing.y = pilot;
      kernel_.frame.sampling = gpu::uvec4(0u, most - pilot, total, frame.sampling.w);
      trace(0u, most - pilot, false, has_plate);
      report.camera_rays = 0;
      for (const std::uint32_t n : counts_)
        report.camera_rays += n;
    }
    report.trace_s = seconds_since(start);

    start = Clock::now();
    const bool adaptive = request.adaptive;
    // Row pairs: an nv12 chroma row is made from two image rows.
    auto resolve = [&](int pair) {
      const int y0 = 2 * pair;
      const int y1 = std::min(y0 + 2, height);
      for (std::size_t i = std::size_t(y0) * width; i < std::size_t(y1) * width; ++i) {
        const std::uint32_t samples = adaptive ? counts_[i] : kernel_.frame.sampling.z;
        composite_[i] = glm::vec4(
            kernel_.resolve_pixel(mixed_[i], real_[i], aux_[i], plate_[i], has_plate, samples)
                .composite,
            0.0f);
      }
      for (const VideoBuffer &out : outputs)
        video::encode_rows(out.format, out.bytes, composite_.data(), y0, y1);
    };
    pool_.run((height + 1) / 2, resolve);
    report.encode_s = seconds_since(start);
    return report;
  }

private:
  static Scene without_plate(Scene scene) {
    scene.plate.reset();
    return scene;
  }

  // Samples [first, end) of every pixel into the accumulators, cleared first
  // when `clear`.
  void trace(std::uint32_t first, std::uint32_t end, bool clear, bool has_plate) {
    kernel_.frame.sampling.x = first;
    kernel_.frame.sampling.y = end;
    const int width = scene_.render.width;
    auto row = [&](int y) {
      for (int x = 0; x < width; ++x) {
        const std::size_t i = std::size_t(y) * width + x;
        if (clear)
          mixed_[i] = real_[i] = aux_[i] = glm::vec4(0.0f);
        kernel_.trace_pixel(std::uint32_t(x), std::uint32_t(y), plate_[i], has_plate, mixed_[i],
                            real_[i], aux_[i]);
      }
    };
    pool_.run(scene_.render.height, row);
  }

  Scene scene_;
  CompiledScene compiled_;
  WorkerPool pool_;
  std::size_t pixels_;
  std::vector<gpu::BvhNode> nodes_;
  cpu::CpuKernel kernel_;
  std::vector<glm::vec4> plate_, composite_;
  std::vector<glm::vec4> mixed_, real_, aux_; // the accumulators
  std::vector<std::uint32_t> counts_;         // adaptive shares
};

} // namespace

std::unique_ptr<FrameRenderer> make_cpu_frame_renderer(const Scene &scene, int threads) {
  return std::make_unique<CpuFrameRenderer>(scene, threads);
}

} // namespace camhead::renderer
