#include "bench_cache.h"

#include <exception>

namespace camhead::bench {

BenchCache &BenchCache::get() {
  static BenchCache cache;
  return cache;
}

const PreparedScene &BenchCache::scene(const BenchScene &scene, int width, int height) {
  const std::string key = scene.name + "/" + std::to_string(width) + "x" + std::to_string(height);
  auto &slot = scenes_[key];
  if (!slot) {
    auto prepared = std::make_unique<PreparedScene>();
    prepared->key = key;
    prepared->scene = load_bench_scene(scene, width, height);
    prepared->compiled = renderer::compile_scene(prepared->scene);
    slot = std::move(prepared);
  }
  return *slot;
}

renderer::GpuTracer *BenchCache::gpu(std::string &error) {
  if (!gpu_tried_) {
    gpu_tried_ = true;
    try {
      gpu_ = std::make_unique<renderer::GpuTracer>(device_);
    } catch (const std::exception &e) {
      gpu_error_ = e.what();
    }
  }
  error = gpu_error_;
  return gpu_.get();
}

renderer::GpuTracer *BenchCache::gpu_with(const PreparedScene &prepared, std::string &error) {
  if (gpu(error) == nullptr) {
    return nullptr;
  }
  if (gpu_loaded_ != prepared.key) {
    gpu_->load(prepared.compiled);
    gpu_loaded_ = prepared.key;
  }
  return gpu_.get();
}

} // namespace camhead::bench
