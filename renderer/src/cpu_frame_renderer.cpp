// The CPU reference as a live frame renderer (frame_renderer.h): the scene
// compiled and the kernel bound once, the per-pixel buffers and the threads
// made once, then per frame passes over the rows: the camera frame into the
// linear plate, the samples (a pilot and a second pass when adaptive; each
// pixel's share of the rays when accumulating, frame_history.h), the
// reconstruction (accumulating frames, defocus_filter.h), and the resolve
// with each output's encoding.
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/frame_history.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/influence_region.h"
#include "cpu_kernel.h"
#include "defocus_filter.h"
#include "frame_checks.h"
#include "pixel_span.h"
#include "ray_shares.h"
#include "video_codec.h"
#include "worker_pool.h"

namespace camhead::renderer {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Accumulating frames: samples every pixel gets before the shares follow
// the noise (enough for a first estimate of it, ray_shares.h).
constexpr std::uint32_t kPilotSamples = 4;

class CpuFrameRenderer final : public FrameRenderer {
public:
  CpuFrameRenderer(const Scene &scene, int threads)
      : scene_(without_plate(scene)), compiled_(compile_scene(scene_)), pool_(threads),
        pixels_(std::size_t(scene_.render.width) * std::size_t(scene_.render.height)),
        plate_(pixels_), composite_(pixels_), mixed_(pixels_, glm::vec4(0.0f)),
        real_(pixels_, glm::vec4(0.0f)), aux_(pixels_, glm::vec4(0.0f)),
        history_counts_(pixels_, 0u), shares_(pixels_, 0u), sigma_(pixels_, 0.0f),
        noise_(pixels_, 0.0f), filtered_mixed_(pixels_), filtered_real_(pixels_),
        scratch_mixed_(pixels_), scratch_real_(pixels_), scratch_weight_(pixels_), blur_(pixels_) {
    const int w = scene_.render.width;
    const int h = scene_.render.height;
    if (w <= 0 || h <= 0 || w % 2 != 0 || h % 2 != 0)
      throw std::invalid_argument(scene.source.string() + ": render: size " + std::to_string(w) +
                                  "x" + std::to_string(h) +
                                  " is not a video frame size (even width and height)");
    kernel_ = cpu::make_cpu_kernel(compiled_, make_frame_params(scene_), nodes_);
    // A region's rows hold at most every other tile as a run of its own.
    const std::size_t runs = (std::size_t(w) + 2 * CAMHEAD_TILE_X - 1) / (2 * CAMHEAD_TILE_X);
    for (std::vector<RowSpan> *spans : {&spans_, &blocks_, &traced_spans_})
      spans->reserve(runs * std::size_t(h));
  }

  std::string executor() const override {
    return "cpu reference, " + std::to_string(pool_.threads()) + " thread" +
           (pool_.threads() == 1 ? "" : "s");
  }

  void prepare(const FrameRequest &request, const std::optional<base::VideoFormat> &plate,
               std::span<const base::VideoFormat>) override {
    gpu::FrameParams frame = make_frame_params(scene_, request.camera, 1);
    frame.image.z = plate ? 1u : 0u;
    if (request.influence_region)
      static_cast<void>(regions_.build(frame));
    history_valid_ = false; // the region it traced is no longer in regions_
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

    if (request.accumulation.enabled && request.adaptive)
      return bad_frame("adaptive frames do not accumulate");
    if (request.accumulation.enabled && request.accumulation.max_samples == 0)
      return bad_frame("a history of at most 0 samples");

    gpu::FrameParams frame = make_frame_params(scene_, request.camera, int(request.rays_per_pixel));
    frame.image.z = has_plate ? 1u : 0u; // the camera frame is the plate
    if (request.seed != 0)
      frame.sampling.w = request.seed;
    const bool continues = request.accumulation.enabled && continues_history(request, frame);
    if (request.accumulation.enabled) {
      if (continues) {
        frame = history_; // its camera and seed, so that the samples stay one pattern's
      } else {
        frame.tracing.z = SAMPLER_SOBOL; // progressive: sample i does not depend on the count
        frame.sampling.z = request.accumulation.max_samples; // the pattern's size
        history_ = frame;
        history_valid_ = true;
        history_by_noise_ = request.accumulation.share_by_noise;
        history_uniform_ = 0;
        history_rays_ = 0;
        history_frames_ = 0;
      }
      ++history_frames_;
      report.history_restarted = !continues;
    } else {
      history_valid_ = false;
    }
    cpu::set_cpu_frame(kernel_, compiled_, frame);
    if (request.accumulation.enabled) // every sample traced on its own: see trace_pixel
      kernel_.frame.tracing.w &= ~TRACING_SKIP_EMPTY_PIXELS;

    Clock::time_point start = Clock::now();
    if (!continues) {
      region_ = request.influence_region ? &regions_.build(frame)
                                         : &regions_.whole_frame(frame.image.x, frame.image.y);
      region_kind_ = request.influence_region;
      spans_.clear();
      blocks_.clear();
      for (const PixelRect &rect : region_->rects)
        for (std::uint32_t y = rect.y0; y < rect.y1; ++y) {
          spans_.push_back({y, rect.x0, rect.x1});
          if ((y - rect.y0) % 2 == 0) // whole tiles: an even number of rows
            blocks_.push_back({y, rect.x0, rect.x1});
        }
    }
    report.traced_pixels = region_->pixels();
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
    if (!continues)
      clear_traced();
    const std::uint32_t total = frame.sampling.z;
    if (request.accumulation.enabled) {
      report.camera_rays = share_rays(request);
      trace_shares(has_plate);
      history_rays_ += report.camera_rays;
      report.history_samples =
          std::uint32_t(history_rays_ / std::max<std::uint64_t>(region_->pixels(), 1));
    } else if (!request.adaptive) {
      trace(0u, total, has_plate);
      report.camera_rays = region_->pixels() * total;
    } else {
      const std::uint32_t pilot = adaptive_pilot(request.adaptive_settings, total);
      kernel_.frame.sampling = gpu::uvec4(0u, pilot, pilot, frame.sampling.w);
      trace(0u, pilot, has_plate);
      // allocate_samples() returns a new vector (adaptive frames only).
      counts_ = allocate_samples(aux_, frame, pilot, request.adaptive_settings, region_);
      const std::uint32_t most = *std::max_element(counts_.begin(), counts_.end());
      kernel_.sample_counts = counts_.data();
      kernel_.frame.tracing.y = pilot;
      kernel_.frame.sampling = gpu::uvec4(0u, most - pilot, total, frame.sampling.w);
      trace(0u, most - pilot, has_plate);
      report.camera_rays = 0;
      for (const std::uint32_t n : counts_)
        report.camera_rays += n;
    }
    // Reconstructed layers are means already.
    const bool filtered = request.accumulation.enabled && request.accumulation.reconstruct;
    if (filtered) {
      cpu::DefocusFilterSettings settings;
      settings.strength = request.accumulation.reconstruct_strength;
      cpu::filter_defocus(
          kernel_.frame, spans_, mixed_, real_, aux_, history_counts_, settings,
          {filtered_mixed_, filtered_real_, scratch_mixed_, scratch_real_, scratch_weight_, blur_},
          pool_);
    }
    report.trace_s = seconds_since(start);

    start = Clock::now();
    const std::uint32_t *per_pixel = request.accumulation.enabled ? history_counts_.data()
                                     : request.adaptive           ? counts_.data()
                                                                  : nullptr;
    // Blocks of two rows: an nv12 chroma row is made from two image rows.
    auto resolve = [&](int y0, int y1, int x0, int x1) {
      for (int y = y0; y < y1; ++y)
        for (std::size_t i = std::size_t(y) * width + x0; i < std::size_t(y) * width + x1; ++i) {
          const std::uint32_t samples = per_pixel != nullptr ? per_pixel[i] : total;
          composite_[i] = glm::vec4(
              filtered && samples > 0 // outside the region the layers are the zeros
                  ? kernel_
                        .resolve_pixel(filtered_mixed_[i], filtered_real_[i], aux_[i], plate_[i],
                                       has_plate, 1u)
                        .composite
                  : kernel_
                        .resolve_pixel(mixed_[i], real_[i], aux_[i], plate_[i], has_plate, samples)
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

  std::span<const glm::vec4> last_composite() const override { return composite_; }

private:
  static Scene without_plate(Scene scene) {
    scene.plate.reset();
    return scene;
  }

  // Whether `frame` may add to the history: the one before accumulated, with
  // the same settings, and the camera moved less than the tolerance.
  bool continues_history(const FrameRequest &request, const gpu::FrameParams &frame) const {
    if (!history_valid_ || request.accumulation.max_samples != history_.sampling.z ||
        request.accumulation.share_by_noise != history_by_noise_ ||
        region_kind_ != request.influence_region)
      return false;
    const double change = frame_change_px(history_, frame, nearest_depth_m(compiled_, history_));
    return change <= request.accumulation.tolerance_px;
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
  using RowSpan = cpu::PixelSpan;

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
      std::fill(&history_counts_[row + span.x0], &history_counts_[row + span.x1], 0u);
    };
    pool_.run(int(traced_spans_.size()), clear);
    traced_spans_ = spans_; // what this frame leaves in them
  }

  // An accumulating frame's rays, pixel by pixel (shares_), within the
  // frame's budget of rays_per_pixel for each pixel of the region; returns
  // their sum. The first kPilotSamples of a history go to every pixel alike;
  // from there, with share_by_noise, where the image still lacks them
  // (ray_shares.h).
  std::uint64_t share_rays(const FrameRequest &request) {
    const std::uint32_t most = request.accumulation.max_samples;
    const std::uint32_t rpp = request.rays_per_pixel;
    const bool by_noise = request.accumulation.share_by_noise && history_uniform_ >= kPilotSamples;
    if (!by_noise) {
      const std::uint32_t k = std::min(rpp, most - std::min(most, history_uniform_));
      for (const RowSpan &span : spans_)
        for (std::size_t i = index(span.y, span.x0); i < index(span.y, span.x1); ++i)
          shares_[i] = k;
      history_uniform_ += k;
      return region_->pixels() * k;
    }
    return cpu::share_rays_by_noise(spans_, scene_.render.width, scene_.render.height, aux_,
                                    history_counts_, rpp, most, history_frames_,
                                    {sigma_, noise_, shares_}, pool_);
  }

  std::size_t index(std::uint32_t y, std::uint32_t x) const {
    return std::size_t(y) * std::size_t(scene_.render.width) + x;
  }

  // Each pixel's share of the frame's rays, the samples after those it holds.
  void trace_shares(bool has_plate) {
    auto row = [&](int k) {
      const RowSpan &span = spans_[std::size_t(k)];
      cpu::CpuKernel kernel = kernel_; // its own sample range per pixel
      for (std::uint32_t x = span.x0; x < span.x1; ++x) {
        const std::size_t i = index(span.y, x);
        if (shares_[i] == 0)
          continue;
        kernel.frame.sampling.x = history_counts_[i];
        kernel.frame.sampling.y = history_counts_[i] + shares_[i];
        kernel.trace_pixel(x, span.y, plate_[i], has_plate, mixed_[i], real_[i], aux_[i]);
        history_counts_[i] += shares_[i];
      }
    };
    pool_.run(int(spans_.size()), row);
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
  InfluenceRegionBuilder regions_{compiled_};
  const InfluenceRegion *region_ = nullptr; // this frame's, in regions_
  std::vector<RowSpan> spans_;              // this frame's region, row by row
  std::vector<RowSpan> blocks_;             // ... and by pairs of rows
  std::vector<RowSpan> traced_spans_;       // what the accumulators hold
  // The history: the accumulators' camera and pattern, and what they hold.
  gpu::FrameParams history_{};
  bool history_valid_ = false;
  bool history_by_noise_ = false;
  std::uint32_t history_uniform_ = 0; // samples every pixel has (the uniform frames')
  std::uint64_t history_rays_ = 0;
  std::uint32_t history_frames_ = 0;
  std::vector<std::uint32_t> history_counts_; // samples per pixel
  std::vector<std::uint32_t> shares_;         // this frame's rays per pixel
  std::vector<float> sigma_, noise_;          // each pixel's noise, for the shares
  // The reconstruction's means and passes (defocus_filter.h).
  std::vector<glm::vec4> filtered_mixed_, filtered_real_, scratch_mixed_, scratch_real_;
  std::vector<float> scratch_weight_, blur_;
  bool region_kind_ = true; // the region's: request.influence_region
};

} // namespace

std::unique_ptr<FrameRenderer> make_cpu_frame_renderer(const Scene &scene, int threads) {
  return std::make_unique<CpuFrameRenderer>(scene, threads);
}

} // namespace camhead::renderer
