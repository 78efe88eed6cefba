// The CPU reference as a live frame renderer (frame_renderer.h): the scene
// compiled and the kernel bound once, the per-pixel buffers and the threads
// made once, then per frame passes over the rows: the camera frame into the
// linear plate, the samples (a pilot and a second pass when adaptive; each
// pixel's share of the rays when accumulating, frame_history.h; a new
// history's first, the last frames' samples moved through the new lens,
// sample_store.h), the reconstruction (accumulating frames,
// defocus_filter.h), and the resolve with each output's encoding.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstddef>
#include <optional>
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
#include "sample_store.h"
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

// The samples kept for reprojection (sample_store.h), in frames of the
// whole picture at one ray per pixel: 40 MB at 720x576, eight frames of 1
// rpp where the influence region is a quarter of the frame.
constexpr std::size_t kStoredFrames = 2;
// The most threads that move the kept samples at once (bands of rows).
constexpr int kMostBands = 8;
// The pass's Sobol' points made once (cpu_kernel.h): as many as a history
// of the default 256 samples, four times over.
constexpr std::size_t kSobolPoints = 1024;

class CpuFrameRenderer final : public FrameRenderer {
public:
  CpuFrameRenderer(const Scene &scene, int threads)
      : scene_(without_plate(scene)), compiled_(compile_scene(scene_)), pool_(threads),
        pixels_(std::size_t(scene_.render.width) * std::size_t(scene_.render.height)),
        plate_(pixels_), composite_(pixels_), mixed_(pixels_, glm::vec4(0.0f)),
        real_(pixels_, glm::vec4(0.0f)), aux_(pixels_, glm::vec4(0.0f)),
        history_counts_(pixels_, 0u), own_counts_(pixels_, 0u),
        row_pixels_(std::size_t(std::max(scene_.render.height, 0))), shares_(pixels_, 0u),
        sigma_(pixels_, 0.0f), noise_(pixels_, 0.0f), filtered_mixed_(pixels_),
        filtered_real_(pixels_), scratch_mixed_(pixels_), scratch_real_(pixels_),
        scratch_weight_(pixels_), blur_(pixels_), filter_gaussian_(pixels_) {
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
    span_firsts_.reserve(runs * std::size_t(h));
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
    if (request.accumulation.enabled && request.accumulation.reproject && !store_.reserved())
      store_.reserve(kStoredFrames * pixels_, frame.image.x, frame.image.y);
    history_valid_ = false; // the region it traced is no longer in regions_
  }

  FrameReport render(const FrameRequest &asked, const VideoFrame &plate,
                     std::span<const VideoBuffer> outputs) override {
    FrameReport report;
    const int width = scene_.render.width;
    const int height = scene_.render.height;
    const bool has_plate = !plate.bytes.empty();
    if (std::string reason = check_frames(plate, outputs, width, height); !reason.empty())
      return bad_frame(std::move(reason));
    if (std::string reason = check_request(asked, has_plate); !reason.empty())
      return bad_frame(std::move(reason));
    const FrameRequest request = as_rendered(asked);

    gpu::FrameParams frame = make_frame_params(scene_, request.camera, int(request.rays_per_pixel));
    frame.image.z = has_plate ? 1u : 0u; // the camera frame is the plate
    if (request.seed != 0)
      frame.sampling.w = request.seed;
    const bool continues = request.accumulation.enabled && continues_history(request, frame);
    const bool reprojects = request.accumulation.enabled && request.accumulation.reproject;
    if (!reprojects)
      store_.clear();            // what it holds would be older than the frames between
    else if (!store_.reserved()) // prepare() reserves it
      store_.reserve(kStoredFrames * pixels_, frame.image.x, frame.image.y);
    if (request.accumulation.enabled) {
      if (continues) {
        frame = history_; // its camera and seed, so that the samples stay one pattern's
      } else {
        frame.tracing.z = SAMPLER_SOBOL; // progressive: sample i does not depend on the count
        frame.sampling.z = request.accumulation.max_samples; // the pattern's size
        // After a change of the lens alone the pattern goes on where the
        // last history's left off (its seed, the indices after those it
        // traced): a sample moved within its pixel and the new ones are then
        // one pattern's, stratified together, not independent.
        const bool goes_on = reprojects && history_valid_ && history_all_uniform_ &&
                             history_.sampling.z == frame.sampling.z &&
                             cpu::same_view(history_, frame) &&
                             pattern_base_ + history_uniform_ < frame.sampling.z / 2;
        pattern_base_ = goes_on ? pattern_base_ + history_uniform_ : 0;
        if (goes_on)
          frame.sampling.w = history_.sampling.w;
        history_all_uniform_ = true;
        history_ = frame;
        history_valid_ = true;
        history_by_noise_ = request.accumulation.share_by_noise;
        history_uniform_ = 0;
        history_rays_ = 0;
        history_moved_ = 0;
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
    sobol_points_.give(kernel_, frame);

    Clock::time_point start = Clock::now();
    if (!continues) {
      region_ = request.plate_only         ? &regions_.none(frame.image.x, frame.image.y)
                : request.influence_region ? &regions_.build(frame)
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
    report.region = region_->rects;
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
    if (!continues && reprojects) {
      report.reprojected_samples =
          reproject_into_history(has_plate, request.accumulation.reproject_frames);
      history_rays_ += report.reprojected_samples;
      history_moved_ = report.reprojected_samples;
    }
    const std::uint32_t total = frame.sampling.z;
    const Clock::time_point rays_start = Clock::now();
    if (request.accumulation.enabled) {
      report.camera_rays = share_rays(request);
      // A frame that traces every pixel alike is kept for the frames after
      // a lens change; one shared by noise is not (its samples are not
      // uniform over the region).
      std::span<cpu::StoredSample> kept;
      if (reprojects && uniform_share_ > 0)
        kept = store_.add_frame(kernel_.frame, *region_, report.camera_rays);
      trace_shares(has_plate, kept);
      if (first_frame_rest_ > 0.0) {
        const cpu::FirstFrameShared rest = share_first_frame_rest(request, has_plate);
        report.camera_rays += rest.rays;
        trace_shares(has_plate, {});
        history_uniform_ += rest.least; // every pixel holds them
        if (rest.uneven)
          history_all_uniform_ = false; // its pixels hold counts of their own
      }
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
    report.rays_s = seconds_since(rays_start);
    // Reconstructed layers are means already. A frame that added no ray to
    // the history (a whole one, or one whose shares by noise all came out
    // 0) has the means of the frame before, if that one reconstructed them
    // as this one would.
    const bool filtered = request.accumulation.enabled && request.accumulation.reconstruct;
    const bool kept = continues && report.camera_rays == 0 && filtered_strength_ &&
                      *filtered_strength_ == request.accumulation.reconstruct_strength;
    filtered_strength_.reset(); // until the means are whole again
    if (filtered && !kept) {
      cpu::filter_defocus(kernel_.frame, spans_, mixed_, real_, aux_, history_counts_,
                          {.strength = request.accumulation.reconstruct_strength,
                           .lend_up_to_own = history_moved_ == 0},
                          {filtered_mixed_, filtered_real_, scratch_mixed_, scratch_real_,
                           scratch_weight_, blur_, filter_gaussian_},
                          pool_);
    }
    filtered_strength_ =
        filtered ? std::optional(request.accumulation.reconstruct_strength) : std::nullopt;
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
          video::copy_row(plate.format, plate.bytes, out.format, out.bytes, y);
      };
      pool_.run(int(base::frame_rows(plate.format)), copy);
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
      std::fill(&own_counts_[row + span.x0], &own_counts_[row + span.x1], 0u);
    };
    pool_.run(int(traced_spans_.size()), clear);
    traced_spans_ = spans_; // what this frame leaves in them
  }

  // An accumulating frame's rays, pixel by pixel (shares_), within the
  // frame's budget of rays_per_pixel for each pixel of the region; returns
  // their sum. The first kPilotSamples of a history go to every pixel alike
  // (but a first frame's rays after the first: share_first_frame_rest);
  // from there, with share_by_noise, where the image still lacks them
  // (ray_shares.h).
  std::uint64_t share_rays(const FrameRequest &request) {
    // Pattern indices from pattern_base_ on, below the pattern's size.
    const std::uint32_t most = request.accumulation.max_samples - pattern_base_;
    const std::uint32_t rpp = request.rays_per_pixel;
    // The frames that share their rays unevenly spend the budget's fraction
    // of a ray too (FrameRequest::extra_rays_per_pixel).
    const double mean = rpp + double(request.extra_rays_per_pixel);
    const bool by_noise = request.accumulation.share_by_noise && history_uniform_ >= kPilotSamples;
    // A history's first frame with nothing moved into it and more than a
    // ray a pixel to give: a ray each here, the rest after it is traced.
    first_frame_rest_ = request.accumulation.share_by_noise && history_frames_ == 1 &&
                                history_rays_ == 0 && mean > 1.0 && most > 1
                            ? mean - 1.0
                            : 0.0;
    uniform_share_ = 0;
    history_all_uniform_ = history_all_uniform_ && !by_noise;
    if (!by_noise) {
      const std::uint32_t k =
          std::min(first_frame_rest_ > 0.0 ? 1u : rpp, most - std::min(most, history_uniform_));
      // No pixel goes past its pattern's end: after a first frame that gave
      // its rays unevenly, some pixels hold more than the others.
      bool alike = true;
      std::uint64_t rays = 0;
      span_firsts_.clear();
      std::size_t first = 0;
      for (const RowSpan &span : spans_) {
        for (std::size_t i = index(span.y, span.x0); i < index(span.y, span.x1); ++i) {
          shares_[i] = std::min(k, cpu::sample_room(most, own_counts_[i]));
          alike = alike && shares_[i] == k;
          rays += shares_[i];
        }
        span_firsts_.push_back(first);
        first += std::size_t(span.x1 - span.x0) * k;
      }
      history_uniform_ += k;
      uniform_share_ = alike ? k : 0; // a frame of uneven shares is not kept (sample_store.h)
      return rays;
    }
    return cpu::share_rays_by_noise(
        spans_, scene_.render.width, scene_.render.height, aux_, history_counts_, own_counts_, mean,
        request.accumulation.max_samples, most, history_frames_, {sigma_, noise_, shares_}, pool_);
  }

  // A first frame's rays after its first: alike where the lens blurs, by
  // the neighbours' spread where it is sharp (ray_shares.h).
  cpu::FirstFrameShared share_first_frame_rest(const FrameRequest &request, bool has_plate) {
    cpu::FirstFrameShares settings;
    settings.rest = first_frame_rest_;
    settings.reconstruct_strength =
        request.accumulation.reconstruct ? request.accumulation.reconstruct_strength : 0.0;
    settings.most = request.accumulation.max_samples;
    settings.pattern_room = request.accumulation.max_samples - pattern_base_;
    settings.rounding_key = kernel_.frame.sampling.w ^ 0x5bd1e995u; // the frame's seed
    return cpu::share_first_frame_rays(spans_, kernel_.frame, aux_, plate_, has_plate,
                                       history_counts_, own_counts_, settings,
                                       {sigma_, noise_, shares_}, pool_);
  }

  std::size_t index(std::uint32_t y, std::uint32_t x) const {
    return std::size_t(y) * std::size_t(scene_.render.width) + x;
  }

  // Each pixel's share of the frame's rays, the samples of its pattern after
  // those it traced; into `kept` too where it is not empty (a frame of
  // uniform shares: span k's samples from span_firsts_[k] on).
  void trace_shares(bool has_plate, std::span<cpu::StoredSample> kept) {
    auto row = [&](int k) {
      const RowSpan &span = spans_[std::size_t(k)];
      cpu::CpuKernel kernel = kernel_; // its own sample range per pixel
      cpu::StoredSample *out = kept.empty() ? nullptr : kept.data() + span_firsts_[std::size_t(k)];
      for (std::uint32_t x = span.x0; x < span.x1; ++x) {
        const std::size_t i = index(span.y, x);
        if (shares_[i] == 0)
          continue;
        kernel.frame.sampling.x = pattern_base_ + own_counts_[i];
        kernel.frame.sampling.y = pattern_base_ + own_counts_[i] + shares_[i];
        if (out == nullptr)
          kernel.trace_pixel(x, span.y, plate_[i], has_plate, mixed_[i], real_[i], aux_[i]);
        else
          out = trace_and_keep(kernel, x, span.y, has_plate, out);
        own_counts_[i] += shares_[i];
        history_counts_[i] += shares_[i];
      }
    };
    pool_.run(int(spans_.size()), row);
  }

  // trace_pixel()'s samples (uniform, every one traced), each kept as
  // sample_store.h keeps it: its ray in the camera's frame and its result.
  cpu::StoredSample *trace_and_keep(cpu::CpuKernel &kernel, std::uint32_t x, std::uint32_t y,
                                    bool has_plate, cpu::StoredSample *out) {
    const std::size_t i = index(y, x);
    const gpu::FrameParams &f = kernel.frame;
    const glm::vec3 pupil(f.cam_position), right(f.cam_right), up(f.cam_up), forward(f.cam_forward);
    const std::uint32_t pattern = kernel.pixel_pattern_for(x, y, f.image.x, f.sampling.w);
    const cpu::CpuKernel::SobolPixel sobol = kernel.camera_sobol_pixel(x, y, f.sampling.w);
    for (std::uint32_t s = f.sampling.x; s < f.sampling.y; ++s) {
      const cpu::CpuKernel::Ray ray = kernel.camera_ray(x, y, s, f.sampling.z, pattern, sobol);
      const cpu::CpuKernel::SampleResult r = kernel.trace_sample(ray, s, f.sampling.z, pattern);
      kernel.accumulate_sample(r, 1.0f, plate_[i], has_plate, mixed_[i], real_[i], aux_[i]);
      const float along = glm::dot(ray.dir, forward);
      const glm::vec3 offset = ray.origin - pupil;
      *out++ = {glm::vec4(glm::dot(ray.dir, right) / along, glm::dot(ray.dir, up) / along,
                          glm::dot(offset, right), glm::dot(offset, up)),
                glm::vec4(r.mixed, r.is_virtual ? 1.0f : 0.0f),
                glm::vec4(r.real, r.hit ? r.depth : -1.0f)};
    }
    return out;
  }

  // The kept samples of the last frames, moved into this frame's camera
  // (kernel_.frame) where they land in its region; returns how many. The
  // threads take bands of rows holding alike shares of the region.
  std::uint64_t reproject_into_history(bool has_plate, std::uint32_t frames) {
    store_.begin_reprojection(kernel_.frame, *region_, frames);
    auto add = [&](std::size_t i, const cpu::StoredSample &s) {
      cpu::CpuKernel::SampleResult r;
      r.mixed = glm::vec3(s.mixed);
      r.real = glm::vec3(s.real);
      r.is_virtual = s.mixed.w > 0.5f;
      r.hit = s.real.w >= 0.0f;
      r.depth = s.real.w;
      kernel_.accumulate_sample(r, 1.0f, plate_[i], has_plate, mixed_[i], real_[i], aux_[i]);
      ++history_counts_[i];
    };
    const int bands = std::min(pool_.threads(), kMostBands);
    std::array<std::uint32_t, kMostBands + 1> rows{};
    std::array<std::uint64_t, kMostBands> given{};
    // The region's pixels row by row (its spans come rectangle by
    // rectangle), then cut where each band's share is reached: the bands
    // are disjoint and in order.
    std::fill(row_pixels_.begin(), row_pixels_.end(), 0u);
    for (const RowSpan &span : spans_)
      row_pixels_[span.y] += span.x1 - span.x0;
    const std::uint64_t pixels = region_->pixels();
    std::uint64_t seen = 0;
    int band = 0;
    for (std::uint32_t y = 0; y < row_pixels_.size(); ++y) {
      while (band < bands - 1 && seen >= pixels * std::uint64_t(band + 1) / std::uint64_t(bands))
        rows[std::size_t(++band)] = y;
      seen += row_pixels_[y];
    }
    while (band < bands)
      rows[std::size_t(++band)] = std::uint32_t(scene_.render.height);
    auto rows_of_band = [&](int b) {
      given[std::size_t(b)] =
          store_.reproject_rows(rows[std::size_t(b)], rows[std::size_t(b) + 1], add);
    };
    pool_.run(bands, rows_of_band);
    std::uint64_t total = 0;
    for (int b = 0; b < bands; ++b)
      total += given[std::size_t(b)];
    return total;
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
  std::uint64_t history_moved_ = 0; // of them moved from the frames before
  std::uint32_t history_frames_ = 0;
  std::vector<std::uint32_t> history_counts_; // samples per pixel
  // ... of them traced for this history (its pattern's next index); the
  // rest came from the frames before, moved (sample_store.h).
  std::vector<std::uint32_t> own_counts_;
  cpu::SampleStore store_;
  // Where this history's pattern starts (a pull's go on: see render()), and
  // whether all of its frames shared their rays alike.
  std::uint32_t pattern_base_ = 0;
  bool history_all_uniform_ = true;
  std::vector<std::uint32_t> row_pixels_; // the region's pixels in each row
  std::uint32_t uniform_share_ = 0;       // this frame's rays per pixel, if alike
  double first_frame_rest_ = 0.0;         // ... and a pixel's more, a mean, shared after
  std::vector<std::size_t> span_firsts_;  // ... and where each span's go in store_
  std::vector<std::uint32_t> shares_;     // this frame's rays per pixel
  std::vector<float> sigma_, noise_;      // each pixel's noise, for the shares
  // The reconstruction's means and passes (defocus_filter.h).
  std::vector<glm::vec4> filtered_mixed_, filtered_real_, scratch_mixed_, scratch_real_;
  std::vector<float> scratch_weight_, blur_;
  std::vector<cpu::DefocusGaussian> filter_gaussian_;
  // The strength whose means filtered_* hold, of the accumulators as the
  // last frame left them; none where it did not reconstruct.
  std::optional<double> filtered_strength_;
  bool region_kind_ = true;                         // the region's: request.influence_region
  cpu::SobolPointTable sobol_points_{kSobolPoints}; // the pass's, for the kernel
};

} // namespace

std::unique_ptr<FrameRenderer> make_cpu_frame_renderer(const Scene &scene, int threads) {
  return std::make_unique<CpuFrameRenderer>(scene, threads);
}

} // namespace camhead::renderer
