// The CPU reference as a live frame renderer (frame_renderer.h): the scene
// compiled and the kernel bound once, the per-pixel buffers and the threads
// made once, then per frame four passes over the rows: the camera frame into
// the linear plate, the samples (a pilot and a second pass when adaptive),
// and the resolve with each output's encoding.
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/influence_region.h"
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
        plate_(pixels_), composite_(pixels_), mixed_(pixels_, glm::vec4(0.0f)),
        real_(pixels_, glm::vec4(0.0f)), aux_(pixels_, glm::vec4(0.0f)) {
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
    region_ = request.influence_region ? influence_region(compiled_, frame)
                                       : whole_frame_region(frame.image.x, frame.image.y);
    spans_.clear();
    blocks_.clear();
    for (const PixelRect &rect : region_.rects)
      for (std::uint32_t y = rect.y0; y < rect.y1; ++y) {
        spans_.push_back({y, rect.x0, rect.x1});
        if ((y - rect.y0) % 2 == 0) // whole tiles: an even number of rows
          blocks_.push_back({y, rect.x0, rect.x1});
      }
    report.traced_pixels = region_.pixels();
    report.frame_pixels = pixels_;
    // Outside the region the composite is the camera image, and in the
    // camera frame's own format the way through linear RGB and back gives
    // its bytes back exactly (frame_renderer_test.cpp): such outputs take
    // those bytes as they are, and only the region is converted, into the
    // plate and out of the composite.
    bool camera_format_only = has_plate;
    for (const VideoBuffer &out : outputs)
      camera_format_only = camera_format_only && same_pixels(out.format, plate.format);
    auto decode_all = [&](int y) {
      video::decode_row(plate.format, plate.bytes, y, &plate_[std::size_t(y) * width]);
    };
    auto decode_region = [&](int k) {
      const RowSpan &s = spans_[std::size_t(k)];
      video::decode_row(plate.format, plate.bytes, int(s.y), &plate_[std::size_t(s.y) * width],
                        int(s.x0), int(s.x1));
    };
    if (camera_format_only)
      pool_.run(int(spans_.size()), decode_region);
    else if (has_plate)
      pool_.run(height, decode_all);
    report.decode_s = seconds_since(start);

    start = Clock::now();
    clear_traced();
    const std::uint32_t total = frame.sampling.z;
    if (!request.adaptive) {
      trace(0u, total, has_plate);
      report.camera_rays = region_.pixels() * total;
    } else {
      const std::uint32_t pilot = adaptive_pilot(request.adaptive_settings, total);
      kernel_.frame.sampling = gpu::uvec4(0u, pilot, pilot, frame.sampling.w);
      trace(0u, pilot, has_plate);
      // allocate_samples() returns a new vector: the one allocation a live
      // frame makes, adaptive frames only.
      counts_ = allocate_samples(aux_, frame, pilot, request.adaptive_settings, &region_);
      const std::uint32_t most = *std::max_element(counts_.begin(), counts_.end());
      kernel_.sample_counts = counts_.data();
      kernel_.frame.tracing.y = pilot;
      kernel_.frame.sampling = gpu::uvec4(0u, most - pilot, total, frame.sampling.w);
      trace(0u, most - pilot, has_plate);
      report.camera_rays = 0;
      for (const std::uint32_t n : counts_)
        report.camera_rays += n;
    }
    report.trace_s = seconds_since(start);

    start = Clock::now();
    const bool adaptive = request.adaptive;
    // Blocks of two rows: an nv12 chroma row is made from two image rows.
    auto resolve = [&](int y0, int y1, int x0, int x1) {
      for (int y = y0; y < y1; ++y)
        for (std::size_t i = std::size_t(y) * width + x0; i < std::size_t(y) * width + x1; ++i) {
          const std::uint32_t samples = adaptive ? counts_[i] : kernel_.frame.sampling.z;
          composite_[i] = glm::vec4(
              kernel_.resolve_pixel(mixed_[i], real_[i], aux_[i], plate_[i], has_plate, samples)
                  .composite,
              0.0f);
        }
      for (const VideoBuffer &out : outputs)
        video::encode_rows(out.format, out.bytes, composite_.data(), y0, y1, x0, x1);
    };
    if (camera_format_only) {
      auto copy = [&](int y) {
        for (const VideoBuffer &out : outputs)
          copy_row(plate, out, y);
      };
      pool_.run(copied_rows(plate.format), copy);
      auto resolve_region = [&](int k) {
        const RowSpan &b = blocks_[std::size_t(k)];
        resolve(int(b.y), std::min(int(b.y) + 2, height), int(b.x0), int(b.x1));
      };
      pool_.run(int(blocks_.size()), resolve_region);
    } else {
      auto resolve_all = [&](int pair) {
        resolve(2 * pair, std::min(2 * pair + 2, height), 0, width);
      };
      pool_.run((height + 1) / 2, resolve_all);
    }
    report.encode_s = seconds_since(start);
    return report;
  }

private:
  static Scene without_plate(Scene scene) {
    scene.plate.reset();
    return scene;
  }

  // Rows of every plane (nv12's chroma rows after the luma rows).
  static int copied_rows(const base::VideoFormat &f) {
    return f.height + (f.pixel == base::PixelFormat::nv12 ? f.height / 2 : 0);
  }

  static void copy_row(const VideoFrame &from, const VideoBuffer &to, int row) {
    const std::size_t bytes = base::packed_stride(from.format.pixel, from.format.width);
    std::memcpy(to.bytes.data() + base::row_bytes(to.format) * std::size_t(row),
                from.bytes.data() + base::row_bytes(from.format) * std::size_t(row), bytes);
  }

  // A row's stretch of the region.
  struct RowSpan {
    std::uint32_t y, x0, x1;
  };

  // Zeroes the accumulators of the previous frame's region: outside the
  // frame's own they must be zero, as the resolve (the camera image there)
  // and the adaptive weights' neighbourhoods read them.
  void clear_traced() {
    auto clear = [&](int k) {
      const RowSpan &span = traced_spans_[std::size_t(k)];
      const std::size_t row = std::size_t(span.y) * std::size_t(scene_.render.width);
      std::fill(&mixed_[row + span.x0], &mixed_[row + span.x1], glm::vec4(0.0f));
      std::fill(&real_[row + span.x0], &real_[row + span.x1], glm::vec4(0.0f));
      std::fill(&aux_[row + span.x0], &aux_[row + span.x1], glm::vec4(0.0f));
    };
    pool_.run(int(traced_spans_.size()), clear);
    traced_spans_ = spans_; // what this frame leaves in them
  }

  // Samples [first, end) of the region's pixels into the accumulators.
  void trace(std::uint32_t first, std::uint32_t end, bool has_plate) {
    kernel_.frame.sampling.x = first;
    kernel_.frame.sampling.y = end;
    const int width = scene_.render.width;
    auto row = [&](int k) {
      const RowSpan &span = spans_[std::size_t(k)];
      for (std::uint32_t x = span.x0; x < span.x1; ++x) {
        const std::size_t i = std::size_t(span.y) * width + x;
        kernel_.trace_pixel(x, span.y, plate_[i], has_plate, mixed_[i], real_[i], aux_[i]);
      }
    };
    pool_.run(int(spans_.size()), row);
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
  InfluenceRegion region_;                    // this frame's
  std::vector<RowSpan> spans_;                // this frame's region, row by row
  std::vector<RowSpan> blocks_;               // ... and by pairs of rows
  std::vector<RowSpan> traced_spans_;         // what the accumulators hold
};

} // namespace

std::unique_ptr<FrameRenderer> make_cpu_frame_renderer(const Scene &scene, int threads) {
  return std::make_unique<CpuFrameRenderer>(scene, threads);
}

} // namespace camhead::renderer
