#include "camhead/renderer/cpu_tracer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

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

private:
  int rows_;
  std::atomic<int> next_{0};
};

} // namespace

RenderResult render_cpu(const CompiledScene &scene, const gpu::FrameParams &frame,
                        const ProgressFn &progress, int threads) {
  const auto start = std::chrono::steady_clock::now();
  const int width = int(frame.image.x);
  const int height = int(frame.image.y);
  const std::size_t pixels = std::size_t(width) * height;
  const uint32_t total = frame.sampling.z;

  cpu::CpuKernel kernel;
  kernel.primitives = scene.primitives.data();
  // As the GPU tracer: a scene without nodes traverses the empty BVH.
  const std::vector<gpu::BvhNode> nodes = scene.nodes.empty() ? build_bvh({}).nodes : scene.nodes;
  kernel.nodes = nodes.data();
  // The GPU tracer binds a placeholder for empty arrays; so does this one, as
  // the kernel reads material 0 for rays that miss.
  static const gpu::Material placeholder_material{};
  kernel.materials = scene.materials.empty() ? &placeholder_material : scene.materials.data();
  kernel.lights = scene.lights.data();
  kernel.frame = frame;
  kernel.frame.cam_position -= glm::vec4(scene.origin, 0.0f); // into the compiled frame
  kernel.frame.sampling.x = 0;
  kernel.frame.sampling.y = total;

  std::vector<glm::vec4> acc_mixed(pixels, glm::vec4(0.0f));
  std::vector<glm::vec4> acc_real(pixels, glm::vec4(0.0f));
  std::vector<glm::vec4> acc_aux(pixels, glm::vec4(0.0f));

  if (threads <= 0) {
    threads = int(std::max(1u, std::thread::hardware_concurrency()));
  }
  RowQueue queue(height);
  std::atomic<int> rows_done{0};
  std::mutex progress_mutex;
  auto worker = [&] {
    for (int y = queue.next(); y >= 0; y = queue.next()) {
      for (int x = 0; x < width; ++x) {
        const std::size_t i = std::size_t(y) * width + x;
        kernel.trace_pixel(uint32_t(x), uint32_t(y), acc_mixed[i], acc_real[i], acc_aux[i]);
      }
      const int done = rows_done.fetch_add(1) + 1;
      if (progress) {
        // Report in samples per pixel, as the GPU tracer does.
        std::lock_guard lock(progress_mutex);
        progress(int(std::uint64_t(total) * done / height), int(total));
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) {
    pool.emplace_back(worker);
  }
  worker();
  for (auto &thread : pool) {
    thread.join();
  }

  RenderResult result;
  result.composite = Image(width, height, 3);
  result.mixed = Image(width, height, 3);
  result.real = Image(width, height, 3);
  result.mask = Image(width, height, 1);
  result.depth = Image(width, height, 1);
  const bool has_plate = frame.image.z != 0 && scene.plate.size() == pixels;
  for (std::size_t i = 0; i < pixels; ++i) {
    const glm::vec4 plate = has_plate ? scene.plate[i] : glm::vec4(0.0f);
    const auto r = kernel.resolve_pixel(acc_mixed[i], acc_real[i], acc_aux[i], plate, has_plate);
    for (int c = 0; c < 3; ++c) {
      result.composite.data[i * 3 + c] = r.composite[c];
      result.mixed.data[i * 3 + c] = r.mixed[c];
      result.real.data[i * 3 + c] = r.real[c];
    }
    result.mask.data[i] = r.mask;
    result.depth.data[i] = r.depth;
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.camera_rays = std::uint64_t(pixels) * total;
  return result;
}

} // namespace camhead::renderer
