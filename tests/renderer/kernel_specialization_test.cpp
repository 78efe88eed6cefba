// The GPU tracer builds its trace kernel for the features the scene and the
// frame use (layout.h, KERNEL_*): the driver drops the code of the others.
// Dropping code must not change a single bit of any layer: a kernel built
// without a feature the scene has (a material type, a light type, a sampler
// missed by scene_kernel_features) renders that feature wrong, and the
// GPU-against-CPU tests, which compare within noise, would let a subtle
// difference through. The peer is the same tracer with every feature.
#include <cstdint>
#include <cstring>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/influence_region.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::RenderResult;
using renderer::Scene;

// "" when both images hold the same bits, else where they first differ.
std::string first_difference(const char *layer, const renderer::Image &a,
                             const renderer::Image &b) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels)
    return std::string(layer) + ": sizes differ";
  for (std::size_t i = 0; i < a.data.size(); ++i)
    if (std::memcmp(&a.data[i], &b.data[i], sizeof(float)) != 0)
      return std::string(layer) + ": pixel " + std::to_string(i / std::size_t(a.channels)) +
             " differs, " + std::to_string(a.data[i]) + " against " + std::to_string(b.data[i]);
  return {};
}

void expect_same_bits(const RenderResult &specialized, const RenderResult &every_feature,
                      const std::string &what) {
  for (const auto &[layer, a, b] :
       {std::tuple{"composite", &specialized.composite, &every_feature.composite},
        std::tuple{"I_m", &specialized.mixed, &every_feature.mixed},
        std::tuple{"I_r", &specialized.real, &every_feature.real},
        std::tuple{"mask", &specialized.mask, &every_feature.mask},
        std::tuple{"depth", &specialized.depth, &every_feature.depth}})
    EXPECT_EQ(first_difference(layer, *a, *b), "") << what;
  EXPECT_EQ(specialized.display, every_feature.display) << what << ": display image";
  EXPECT_EQ(specialized.sample_counts, every_feature.sample_counts) << what << ": sample counts";
}

// The scenes: the reference scenes, the demo, the rig's, and random ones
// whose features are random subsets (spheres or boxes, diffuse, mirror,
// glass and emitting materials, point, area and sun lights), with a
// virtual glass ball before a lamp for many bounces.
std::vector<Scene> scenes_of_every_kind() {
  std::vector<Scene> scenes = test::small_reference_scenes();
  for (std::uint32_t seed = 1; seed <= 24; ++seed)
    scenes.push_back(test::random_scene(seed));
  scenes.push_back(test::glass_ball_before_lamp(2.8f, 4.0f));
  return scenes;
}

// Each scene's frame three ways, as still and live frames are rendered:
// CMJ samples over every pixel; Sobol' samples with empty pixels skipped
// (both frame features of the kernel); adaptive over the influence region
// (the kernel that reads the queue).
TEST(KernelSpecialization, EveryLayerHasTheBitsOfTheKernelWithEveryFeature) {
  CAMHEAD_REQUIRE_VULKAN();
  renderer::GpuTracer tracer;
  const auto both = [&](const auto &render) {
    tracer.set_kernel_specialization(true);
    RenderResult specialized = render();
    tracer.set_kernel_specialization(false);
    RenderResult every_feature = render();
    return std::pair(std::move(specialized), std::move(every_feature));
  };
  for (const Scene &scene : scenes_of_every_kind()) {
    const renderer::CompiledScene compiled = renderer::compile_scene(scene);
    tracer.load(compiled);
    const std::string name = scene.source.string();

    const renderer::gpu::FrameParams cmj = renderer::make_frame_params(scene, 4);
    const auto [a, b] = both([&] { return tracer.render(cmj); });
    expect_same_bits(a, b, name + ", CMJ samples");

    renderer::gpu::FrameParams sobol = cmj;
    sobol.tracing.z = SAMPLER_SOBOL;
    sobol.tracing.w |= TRACING_SKIP_EMPTY_PIXELS;
    const auto [c, d] = both([&] { return tracer.render(sobol); });
    expect_same_bits(c, d, name + ", Sobol' samples, empty pixels skipped");

    const renderer::InfluenceRegion region = renderer::influence_region(compiled, cmj);
    const auto [e, f] = both([&] {
      return tracer.render_adaptive(cmj, {}, {}, renderer::LayerSelection::all(), &region);
    });
    expect_same_bits(e, f, name + ", adaptive over the influence region");
  }
}

} // namespace
} // namespace camhead
