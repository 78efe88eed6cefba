// State that the benchmarks of one process share: scenes compiled once per
// size, and one GpuTracer (creating a Vulkan device and its pipelines takes
// longer than a small frame). Benchmarks run one at a time, on the main
// thread; nothing here is thread-safe.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "bench_scenes.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/gpu_tracer.h"

namespace camhead::bench {

struct PreparedScene {
  std::string key; // name and size
  renderer::Scene scene;
  renderer::CompiledScene compiled;
};

class BenchCache {
public:
  static BenchCache &get();

  // Chooses the Vulkan device for the GPU benchmarks (GpuTracer's rule).
  void set_device(std::string device) { device_ = std::move(device); }

  // Loads and compiles on first use.
  const PreparedScene &scene(const BenchScene &scene, int width, int height);

  // The tracer, created on first use; nullptr and `error` when no Vulkan
  // device could be opened.
  renderer::GpuTracer *gpu(std::string &error);

  // The tracer with `prepared` loaded (uploaded when another scene was).
  renderer::GpuTracer *gpu_with(const PreparedScene &prepared, std::string &error);

  // Destroys the tracer. main() calls it before returning: a Vulkan device
  // destroyed by a static destructor can outlive the driver (the NVIDIA
  // driver crashes at exit then).
  void release_gpu() {
    gpu_.reset();
    gpu_loaded_.clear();
  }

  // True the first time a given key is seen: the caller renders one
  // untimed frame, so that the first timed frame pays for no first use
  // (lavapipe compiles shader variants lazily, buffers are touched first).
  bool first_use(const std::string &key) { return warmed_.emplace(key, true).second; }

private:
  std::string device_;
  std::map<std::string, std::unique_ptr<PreparedScene>> scenes_;
  std::unique_ptr<renderer::GpuTracer> gpu_;
  std::string gpu_error_;
  bool gpu_tried_ = false;
  std::string gpu_loaded_;
  std::map<std::string, bool> warmed_;
};

} // namespace camhead::bench
