// The scenes and frame settings that camhead's benchmarks and the Embree peer
// share, so that every figure in bench/RESULTS.md names the same work.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "camhead/renderer/scene.h"

namespace camhead::bench {

// A scene the benchmarks know by a short name: "ar_basic" (the Cycles
// reference scene, tests/assets/reference), "ar_demo" (scenes/ar_demo.json, with the
// bunny), or either with "_primary" appended (primary_only() below).
struct BenchScene {
  std::string name;
  std::filesystem::path file;
  bool primary_only = false;
};

// The source tree: the CAMHEAD_SOURCE_DIR environment variable if set, else
// the one the build was configured from.
[[nodiscard]] std::filesystem::path source_dir();

// ar_basic, ar_demo and their primary-only variants, in source_dir().
[[nodiscard]] std::vector<BenchScene> bench_scenes();
[[nodiscard]] BenchScene find_bench_scene(const std::string &name_or_file);

// Loads the scene at width x height. A plate of another size is dropped (it
// only costs one read per pixel), as `camhead bench` does. Throws SceneError.
[[nodiscard]] renderer::Scene load_bench_scene(const BenchScene &scene, int width, int height);

// The same geometry with no lights, every material diffuse, every object
// part of the real proxy and no bounces: each camera ray then makes exactly
// one closest-hit query (no shadow rays, no real-proxy ray behind a virtual
// object, no mirror or glass continuation). This is the work that a
// primary-ray tracer such as Embree's closest-hit query does, plus camhead's
// sampling, accumulation and compositing.
[[nodiscard]] renderer::Scene primary_only(renderer::Scene scene);

} // namespace camhead::bench
