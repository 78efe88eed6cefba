#include "camhead/renderer/cpu_tracer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/bvh.h"
#include "cpu_kernel.h"

namespace camhead::renderer {
namespace {

// Rows are handed out one at a time: cheap to balance, and a row of the
// same pixels always gets the same samples whatever the thread count.
class RowQueue {
public:
  explicit RowQueue(int rows) : rows_(rows) {}
  [[nodiscard]] int next() {
    int row = next_.fetch_add(1);
    return row < rows_ ? row : -1;
  }
  // No more rows for anyone.
  void cancel() { next_ = rows_; }

private:
  int rows_;
  std::atomic<int> next_{0};
};

} // namespace

cpu::CpuKernel cpu::make_cpu_kernel(const CompiledScene &scene, const gpu::FrameParams &frame,
                                    std::vector<gpu::BvhNode> &nodes) {
  cpu::CpuKernel kernel;
  // Rays that miss read primitive 0 (and ignore it), as on the GPU, which
  // binds a zeroed placeholder for an empty array.
  static const gpu::Primitive placeholder_primitive{};
  kernel.primitives = scene.primitives.empty() ? &placeholder_primitive : scene.primitives.data();
  // As the GPU tracer: a scene without nodes traverses the empty BVH.
  nodes = scene.nodes.empty() ? build_bvh({}).nodes : scene.nodes;
  kernel.nodes = nodes.data();
  // The GPU tracer binds a placeholder for empty arrays; so does this one, as
  // the kernel reads material 0 for rays that miss.
  static const gpu::Material placeholder_material{};
  kernel.materials = scene.materials.empty() ? &placeholder_material : scene.materials.data();
  kernel.lights = scene.lights.data();
  kernel.surfaces = scene.surfaces.data(); // read only through a textured material
  cpu::set_cpu_frame(kernel, scene, frame);
  return kernel;
}

void cpu::set_cpu_frame(CpuKernel &kernel, const CompiledScene &scene,
                        const gpu::FrameParams &frame) {
  kernel.frame = frame;
  kernel.frame.cam_position -= glm::vec4(scene.origin, 0.0f); // into the compiled frame
  kernel.frame.tracing.y = 0u;                                // uniform unless set below
  // On a CPU the test costs less than the samples it saves, however much of
  // the frame the scene covers (layout.h).
  kernel.frame.tracing.w |= TRACING_SKIP_EMPTY_PIXELS;
  kernel.sample_counts = nullptr;
}

namespace {

// The three accumulators of every pixel.
struct Accumulators {
  explicit Accumulators(std::size_t pixels)
      : mixed(pixels, glm::vec4(0.0f)), real(pixels, glm::vec4(0.0f)),
        aux(pixels, glm::vec4(0.0f)) {}
  std::vector<glm::vec4> mixed, real, aux;
};

// A row's stretch of the pixels to trace.
struct RowSpan {
  std::uint32_t y, x0, x1;
};

// The region's rows, or every row of the frame.
std::vector<RowSpan> row_spans(const cpu::CpuKernel &kernel, const InfluenceRegion *region) {
  const InfluenceRegion whole = whole_frame_region(kernel.frame.image.x, kernel.frame.image.y);
  std::vector<RowSpan> spans;
  for (const PixelRect &rect : (region != nullptr ? *region : whole).rects)
    for (std::uint32_t y = rect.y0; y < rect.y1; ++y)
      spans.push_back({y, rect.x0, rect.x1});
  return spans;
}

// Runs kernel.trace_pixel over the pixels of `spans` on `threads` threads;
// `report` gets the fraction of spans done.
void trace_all(cpu::CpuKernel &kernel, const CompiledScene &scene, Accumulators &acc,
               const std::vector<RowSpan> &spans, int threads,
               const std::function<void(double)> &report) {
  const int width = int(kernel.frame.image.x);
  const std::size_t pixels = std::size_t(width) * kernel.frame.image.y;
  const bool has_plate = kernel.frame.image.z != 0;
  if (threads <= 0) {
    threads = int(std::max(1u, std::thread::hardware_concurrency()));
  }
  RowQueue queue(int(spans.size()));
  std::atomic<int> rows_done{0};
  std::mutex progress_mutex;
  auto worker = [&] {
    for (int next = queue.next(); next >= 0; next = queue.next()) {
      const RowSpan &span = spans[std::size_t(next)];
      for (std::uint32_t x = span.x0; x < span.x1; ++x) {
        const std::size_t i = std::size_t(span.y) * width + x;
        const glm::vec4 plate =
            has_plate && scene.plate.size() == pixels ? scene.plate[i] : glm::vec4(0.0f);
        kernel.trace_pixel(x, span.y, plate, has_plate, acc.mixed[i], acc.real[i], acc.aux[i]);
      }
      const int done = rows_done.fetch_add(1) + 1;
      if (report) {
        std::lock_guard lock(progress_mutex);
        report(double(done) / double(spans.size()));
      }
    }
  };
  std::vector<std::thread> pool;
  try {
    for (int t = 1; t < threads; ++t) {
      pool.emplace_back(worker);
    }
  } catch (const std::system_error &e) {
    // A machine out of threads (or memory for their stacks): the threads
    // that started stop, and the caller hears why rather than the program
    // aborting on a joinable thread.
    queue.cancel();
    for (auto &thread : pool) {
      thread.join();
    }
    throw std::runtime_error("cannot start thread " + std::to_string(pool.size() + 2) + " of " +
                             std::to_string(threads) + ": " + e.what());
  }
  worker();
  for (auto &thread : pool) {
    thread.join();
  }
}

// Resolves the accumulators into the layers; `counts` per pixel, or empty
// for frame.sampling.z everywhere.
RenderResult resolve_all(cpu::CpuKernel &kernel, const CompiledScene &scene,
                         const Accumulators &acc, const std::vector<std::uint32_t> &counts) {
  const int width = int(kernel.frame.image.x);
  const int height = int(kernel.frame.image.y);
  const std::size_t pixels = std::size_t(width) * height;
  RenderResult result;
  result.composite = Image(width, height, 3);
  result.mixed = Image(width, height, 3);
  result.real = Image(width, height, 3);
  result.mask = Image(width, height, 1);
  result.depth = Image(width, height, 1);
  const bool has_plate = kernel.frame.image.z != 0 && scene.plate.size() == pixels;
  for (std::size_t i = 0; i < pixels; ++i) {
    const glm::vec4 plate = has_plate ? scene.plate[i] : glm::vec4(0.0f);
    const std::uint32_t samples = counts.empty() ? kernel.frame.sampling.z : counts[i];
    const auto r =
        kernel.resolve_pixel(acc.mixed[i], acc.real[i], acc.aux[i], plate, has_plate, samples);
    for (int c = 0; c < 3; ++c) {
      result.composite.data[i * 3 + c] = r.composite[c];
      result.mixed.data[i * 3 + c] = r.mixed[c];
      result.real.data[i * 3 + c] = r.real[c];
    }
    result.mask.data[i] = r.mask;
    result.depth.data[i] = r.depth;
  }
  return result;
}

} // namespace

RenderResult render_cpu(const CompiledScene &scene, const gpu::FrameParams &frame,
                        const ProgressFn &progress, int threads, const InfluenceRegion *region) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t pixels = std::size_t(frame.image.x) * frame.image.y;
  const uint32_t total = frame.sampling.z;
  std::vector<gpu::BvhNode> nodes;
  cpu::CpuKernel kernel = cpu::make_cpu_kernel(scene, frame, nodes);
  kernel.frame.sampling.x = 0;
  kernel.frame.sampling.y = total;
  Accumulators acc(pixels);
  const std::vector<RowSpan> spans = row_spans(kernel, region);
  // Report in samples per pixel, as the GPU tracer does.
  trace_all(kernel, scene, acc, spans, threads, [&](double done) {
    if (progress)
      progress(int(double(total) * done), int(total));
  });
  RenderResult result = resolve_all(kernel, scene, acc, {});
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.camera_rays = (region != nullptr ? region->pixels() : pixels) * total;
  return result;
}

RenderResult render_cpu_adaptive(const CompiledScene &scene, const gpu::FrameParams &frame,
                                 const AdaptiveSampling &settings, const ProgressFn &progress,
                                 int threads, const InfluenceRegion *region) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t pixels = std::size_t(frame.image.x) * frame.image.y;
  const uint32_t total = frame.sampling.z;
  const uint32_t pilot = adaptive_pilot(settings, total);
  std::vector<gpu::BvhNode> nodes;
  cpu::CpuKernel kernel = cpu::make_cpu_kernel(scene, frame, nodes);
  Accumulators acc(pixels);
  const auto report = [&](double done) {
    if (progress)
      progress(int(double(total) * done), int(total));
  };
  // 1. The pilot, a uniform frame of `pilot` samples.
  kernel.frame.sampling = gpu::uvec4(0u, pilot, pilot, frame.sampling.w);
  const std::vector<RowSpan> spans = row_spans(kernel, region);
  trace_all(kernel, scene, acc, spans, threads, [&](double done) { report(done * pilot / total); });
  // 2. The budget.
  const std::vector<std::uint32_t> counts =
      allocate_samples(acc.aux, frame, pilot, settings, region);
  // 3. Each pixel's share.
  const std::uint32_t most = *std::max_element(counts.begin(), counts.end());
  kernel.sample_counts = counts.data();
  kernel.frame.tracing.y = pilot;
  kernel.frame.sampling = gpu::uvec4(0u, most - pilot, total, frame.sampling.w);
  trace_all(kernel, scene, acc, spans, threads,
            [&](double done) { report((pilot + done * (total - pilot)) / total); });
  RenderResult result = resolve_all(kernel, scene, acc, counts);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.camera_rays = std::accumulate(counts.begin(), counts.end(), std::uint64_t(0));
  result.sample_counts = counts;
  return result;
}

} // namespace camhead::renderer
