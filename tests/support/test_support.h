// Shared helpers of the camhead tests: locating files, rendering on either
// executor, and image metrics as tests/assets/reference/compare.py defines them.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/image.h"
#include "camhead/renderer/render_result.h"
#include "camhead/renderer/scene.h"

namespace camhead::test {

// The repository, fixed at configure time, and its copy of the Cycles
// reference scenes and renders (tests/assets/reference/README.md).
[[nodiscard]] std::filesystem::path source_dir();
[[nodiscard]] std::filesystem::path reference_dir();

// True when a Vulkan device is present; tests needing one GTEST_SKIP otherwise.
[[nodiscard]] bool have_vulkan();

// Renders `scene` with `rpp` rays per pixel on the GPU tracer (lavapipe in
// CI) or on the CPU reference.
[[nodiscard]] renderer::RenderResult render_gpu(const renderer::Scene &scene, int rpp);
[[nodiscard]] renderer::RenderResult render_cpu(const renderer::Scene &scene, int rpp);

// The GPU tracer on a hardware GPU; elsewhere the CPU reference, which runs
// the same kernel several times faster than lavapipe does (bench/RESULTS.md).
// For long converged renders whose executor does not matter: the executors
// are held equal by executors_test.cpp.
[[nodiscard]] renderer::RenderResult render_fastest(const renderer::Scene &scene, int rpp);
[[nodiscard]] bool have_hardware_gpu();

// Root mean square difference over all pixels and channels.
[[nodiscard]] double rmse(const renderer::Image &a, const renderer::Image &b);
// rmse / RMS(reference), as compare.py's relRMSE.
[[nodiscard]] double relative_rmse(const renderer::Image &reference, const renderer::Image &test);

// Least-squares slope of log(y) against log(x): the exponent of a power law
// (convergence rates: error ~ N^slope).
[[nodiscard]] double log_log_slope(const std::vector<double> &x, const std::vector<double> &y);

// Every sample finite: no NaN or Inf reaches an output.
[[nodiscard]] bool all_finite(const renderer::Image &image);
// ... in every float layer of a render (composite, mixed, real, mask, depth).
[[nodiscard]] bool all_layers_finite(const renderer::RenderResult &r);

// A fresh folder for one test's files, named after the test and the
// process so that parallel ctest runs never share one; removed afterwards.
class ScratchDir {
public:
  ScratchDir();
  ~ScratchDir();
  ScratchDir(const ScratchDir &) = delete;
  ScratchDir &operator=(const ScratchDir &) = delete;

  [[nodiscard]] const std::filesystem::path &path() const { return path_; }
  // Writes `bytes` to path() / name and returns that path.
  std::filesystem::path write(const std::string &name, const std::string &bytes) const;

private:
  std::filesystem::path path_;
};

// A copy of `scene` at a lower resolution with the same field of view.
[[nodiscard]] renderer::Scene downscaled(renderer::Scene scene, int divisor);

} // namespace camhead::test

// Skips the current test when no Vulkan device exists, saying so.
#define CAMHEAD_REQUIRE_VULKAN()                                                                   \
  do {                                                                                             \
    if (!camhead::test::have_vulkan()) {                                                           \
      GTEST_SKIP() << "no Vulkan device (install mesa-vulkan-drivers for lavapipe)";               \
    }                                                                                              \
  } while (false)
