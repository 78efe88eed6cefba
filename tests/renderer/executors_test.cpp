// The GPU tracer and the CPU reference run the same kernel on the same
// samples; they must agree far more closely than two independent renders.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/scene_loader.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

class Executors : public ::testing::TestWithParam<std::string> {};

TEST_P(Executors, GpuAgreesWithCpuReferenceBelowSamplingNoise) {
  CAMHEAD_REQUIRE_VULKAN();
  constexpr int rpp = 16;
  renderer::Scene scene =
      test::downscaled(renderer::load_scene(test::reference_dir() / (GetParam() + ".json")), 4);
  const renderer::RenderResult gpu = test::render_gpu(scene, rpp);
  const renderer::RenderResult cpu = test::render_cpu(scene, rpp);
  scene.render.seed += 1;
  const renderer::RenderResult cpu_other_seed = test::render_cpu(scene, rpp);

  struct Layer {
    const char *name;
    const renderer::Image &gpu, &cpu, &other;
  };
  for (const Layer &layer :
       {Layer{"composite", gpu.composite, cpu.composite, cpu_other_seed.composite},
        Layer{"mixed", gpu.mixed, cpu.mixed, cpu_other_seed.mixed},
        Layer{"real", gpu.real, cpu.real, cpu_other_seed.real},
        Layer{"mask", gpu.mask, cpu.mask, cpu_other_seed.mask}}) {
    ASSERT_TRUE(test::all_finite(layer.gpu)) << layer.name;
    // Two independent renders differ by sqrt(2) times the noise of one.
    const double noise = test::rmse(layer.cpu, layer.other) / std::sqrt(2.0);
    const double difference = test::rmse(layer.cpu, layer.gpu);
    std::printf("%s %s at %d rpp: GPU vs CPU RMSE %.2e, sampling noise %.2e\n", GetParam().c_str(),
                layer.name, rpp, difference, noise);
    if (noise == 0.0) {
      EXPECT_EQ(difference, 0.0) << layer.name << " is noiseless, so must be identical";
    } else {
      EXPECT_LT(difference, noise) << layer.name;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(ReferenceScenes, Executors, ::testing::Values("boxes", "ar_basic"));

// A hand-made scene with no BVH at all: both executors traverse the empty BVH
// instead of reading past a placeholder, and every ray sees the world.
TEST(Executors, SceneWithoutNodesShowsTheWorldColour) {
  renderer::Scene scene;
  scene.render.width = 8;
  scene.render.height = 4;
  scene.render.world_color = glm::vec3(0.25f, 0.5f, 0.75f);
  scene.materials.push_back({"grey", renderer::MaterialType::diffuse, glm::vec3(0.5f), 1.5f, {}});
  renderer::CompiledScene compiled = renderer::compile_scene(scene);
  compiled.nodes.clear();
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, 2);
  std::vector<renderer::RenderResult> results{renderer::render_cpu(compiled, frame)};
  if (test::have_vulkan()) {
    renderer::GpuTracer tracer;
    tracer.load(compiled);
    results.push_back(tracer.render(frame));
  }
  for (const renderer::RenderResult &r : results) {
    for (std::size_t i = 0; i < r.composite.pixel_count(); ++i) {
      EXPECT_EQ(r.composite.data[i * 3 + 2], 0.75f);
      EXPECT_EQ(r.mask.data[i], 0.0f);
    }
  }
}

} // namespace
} // namespace camhead
