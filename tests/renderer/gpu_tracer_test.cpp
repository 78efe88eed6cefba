// The GPU tracer's plumbing: device choice, upload, batching, progress and
// read-back. The physics is compared against the CPU tracer elsewhere.
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/image_io.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

// Skips the test on machines without any Vulkan device (not even lavapipe).
#define REQUIRE_VULKAN_DEVICE()                                                                    \
  do {                                                                                             \
    if (list_gpu_devices().empty())                                                                \
      GTEST_SKIP() << "no Vulkan device; install mesa-vulkan-drivers for lavapipe";                \
  } while (false)

float uint_bits(std::uint32_t bits) {
  return std::bit_cast<float>(bits);
}

// A diffuse floor triangle and a sphere under one leaf, seen by a camera at
// z = 3 looking down -z.
CompiledScene small_scene(int width, int height, bool lights_and_plate) {
  CompiledScene scene;
  scene.width = width;
  scene.height = height;
  gpu::Primitive triangle{};
  triangle.p0 = {-2.0f, -1.0f, -2.0f, uint_bits(0u | PRIM_TRIANGLE << 24)};
  triangle.p1 = {4.0f, 0.0f, 0.0f, 0.0f};
  triangle.p2 = {0.0f, 0.0f, 4.0f, 0.0f};
  gpu::Primitive sphere{};
  sphere.p0 = {0.0f, 0.0f, 0.0f, uint_bits(1u | PRIM_SPHERE << 24)};
  sphere.p1 = {0.5f, 0.0f, 0.0f, 0.0f};
  scene.primitives = {triangle, sphere};

  gpu::BvhNode leaf{};
  leaf.bmin = {-2.0f, -1.0f, -2.0f, uint_bits(0)};
  leaf.bmax = {2.0f, 0.5f, 2.0f, uint_bits(2)};
  scene.nodes = {leaf};

  gpu::Material diffuse{{0.8f, 0.8f, 0.8f, 0.0f}, {0.0f, 0.0f, 0.0f, uint_bits(MAT_DIFFUSE)}};
  gpu::Material mirror{{0.9f, 0.9f, 0.9f, 0.0f}, {0.0f, 0.0f, 0.0f, uint_bits(MAT_MIRROR)}};
  scene.materials = {diffuse, mirror};

  if (lights_and_plate) {
    gpu::Light point{};
    point.position = {0.0f, 2.0f, 1.0f, uint_bits(LIGHT_POINT)};
    point.emission = {10.0f, 10.0f, 10.0f, 0.0f};
    scene.lights = {point};
    scene.plate.assign(std::size_t(width) * height, glm::vec4(0.2f, 0.3f, 0.4f, 1.0f));
  }
  return scene;
}

gpu::FrameParams small_frame(const CompiledScene &scene, std::uint32_t samples) {
  gpu::FrameParams frame{};
  frame.cam_position = {0.0f, 0.0f, 3.0f, 0.0f};
  frame.cam_right = {1.0f, 0.0f, 0.0f, 0.0f};
  frame.cam_up = {0.0f, 1.0f, 0.0f, 0.0f};
  frame.cam_forward = {0.0f, 0.0f, -1.0f, 0.0f};
  frame.lens = {0.0f, 3.0f, float(scene.width), 1.0f};
  frame.world_color = {0.1f, 0.1f, 0.1f, 0.0f};
  frame.image = {std::uint32_t(scene.width), std::uint32_t(scene.height),
                 scene.plate.empty() ? 0u : 1u, std::uint32_t(scene.lights.size())};
  frame.sampling = {0u, samples, samples, 7u};
  frame.tracing = {4u, std::uint32_t(scene.primitives.size()), std::uint32_t(scene.nodes.size()),
                   0u};
  return frame;
}

void expect_layer_sizes(const RenderResult &result, int width, int height) {
  for (const Image *image : {&result.composite, &result.mixed, &result.real}) {
    EXPECT_EQ(image->width, width);
    EXPECT_EQ(image->height, height);
    EXPECT_EQ(image->channels, 3);
    EXPECT_EQ(image->data.size(), std::size_t(width) * height * 3);
  }
  for (const Image *image : {&result.mask, &result.depth}) {
    EXPECT_EQ(image->width, width);
    EXPECT_EQ(image->height, height);
    EXPECT_EQ(image->channels, 1);
    EXPECT_EQ(image->data.size(), std::size_t(width) * height);
  }
}

TEST(GpuTracerDevices, ListsAtLeastOneDevice) {
  REQUIRE_VULKAN_DEVICE();
  const std::vector<GpuDeviceInfo> devices = list_gpu_devices();
  for (std::size_t i = 0; i < devices.size(); ++i) {
    EXPECT_EQ(devices[i].index, int(i));
    EXPECT_FALSE(devices[i].name.empty());
    const std::string &type = devices[i].type;
    EXPECT_TRUE(type == "cpu" || type == "discrete" || type == "integrated" || type == "virtual" ||
                type == "other")
        << type;
  }
  EXPECT_NE(format_gpu_devices(devices).find(devices[0].name), std::string::npos);
}

TEST(GpuTracerDevices, SelectsByIndexAndByNameSubstring) {
  REQUIRE_VULKAN_DEVICE();
  const std::vector<GpuDeviceInfo> devices = list_gpu_devices();
  EXPECT_EQ(GpuTracer("0").device_name(), devices[0].name);
  // A substring in another case still picks the device.
  const std::string part = devices[0].name.substr(0, 4);
  std::string upper;
  for (char c : part)
    upper += char(std::toupper(static_cast<unsigned char>(c)));
  EXPECT_EQ(GpuTracer(upper).device_name(), devices[0].name);
  // The default prefers a real GPU, and lavapipe where there is none.
  const GpuTracer fallback;
  EXPECT_FALSE(fallback.device_name().empty());
}

TEST(GpuTracerDevices, UnknownDeviceErrorListsTheDevices) {
  REQUIRE_VULKAN_DEVICE();
  const std::vector<GpuDeviceInfo> devices = list_gpu_devices();
  for (const std::string bogus : {"no-such-gpu-xyz", "97"}) {
    try {
      GpuTracer tracer(bogus);
      ADD_FAILURE() << "device '" << bogus << "' was accepted as " << tracer.device_name();
    } catch (const GpuError &e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(bogus), std::string::npos) << message;
      for (const GpuDeviceInfo &device : devices)
        EXPECT_NE(message.find(device.name), std::string::npos) << message;
    }
  }
}

TEST(GpuTracer, RendersInBatchesWithMonotonicProgress) {
  REQUIRE_VULKAN_DEVICE();
  GpuTracer tracer;
  const CompiledScene scene = small_scene(16, 8, true);
  tracer.load(scene);
  const std::uint32_t samples = 40;
  std::vector<int> done;
  const RenderResult result =
      tracer.render(small_frame(scene, samples), [&](int samples_done, int samples_total) {
        EXPECT_EQ(samples_total, int(samples));
        done.push_back(samples_done);
      });
  expect_layer_sizes(result, 16, 8);
  EXPECT_EQ(result.camera_rays, 16u * 8u * samples);
  EXPECT_GT(result.seconds, 0.0);
  ASSERT_FALSE(done.empty());
  EXPECT_EQ(done.front(), 1) << "the first batch is one sample per pixel";
  for (std::size_t i = 1; i < done.size(); ++i)
    EXPECT_GT(done[i], done[i - 1]);
  EXPECT_EQ(done.back(), int(samples));
}

// The 8-bit display image is the composite as write_png() encodes it, with
// the mask as alpha, and asking for it alone returns the same bytes.
TEST(GpuTracer, DisplayImageIsTheSrgbEncodedCompositeWithMaskAlpha) {
  REQUIRE_VULKAN_DEVICE();
  GpuTracer tracer;
  const CompiledScene scene = small_scene(32, 24, true);
  tracer.load(scene);
  const gpu::FrameParams frame = small_frame(scene, 8);
  const RenderResult all = tracer.render(frame);
  ASSERT_EQ(all.display.size(), std::size_t(32) * 24 * 4);
  const auto code = [](float linear) {
    return int(std::nearbyint(linear_to_srgb(linear) * 255.0f));
  };
  int largest = 0, exact = 0, partly_virtual = 0;
  for (std::size_t i = 0; i < std::size_t(32) * 24; ++i) {
    for (int c = 0; c < 3; ++c) {
      const int difference = std::abs(all.display[4 * i + c] - code(all.composite.data[3 * i + c]));
      largest = std::max(largest, difference);
      exact += difference == 0;
    }
    const float mask = all.mask.data[i];
    EXPECT_LE(std::abs(all.display[4 * i + 3] - int(std::nearbyint(mask * 255.0f))), 1) << i;
    partly_virtual += mask > 0.0f && mask < 1.0f;
  }
  std::printf("display vs write_png encoding: %d of %d codes equal, largest difference %d\n", exact,
              32 * 24 * 3, largest);
  EXPECT_LE(largest, 1);
  EXPECT_GT(partly_virtual, 0) << "the scene should have pixels on the sphere's rim";

  const RenderResult alone = tracer.render(frame, {}, LayerSelection::display_only());
  EXPECT_EQ(alone.display, all.display);
  EXPECT_TRUE(alone.composite.data.empty());
  EXPECT_TRUE(alone.mask.data.empty());
}

TEST(GpuTracer, RendersWithoutLightsPlateOrGeometry) {
  REQUIRE_VULKAN_DEVICE();
  GpuTracer tracer;
  CompiledScene scene = small_scene(16, 8, false);
  tracer.load(scene);
  expect_layer_sizes(tracer.render(small_frame(scene, 2)), 16, 8);

  // An empty world: every buffer is a one-element placeholder.
  scene.primitives.clear();
  scene.nodes.clear();
  scene.materials.clear();
  tracer.load(scene);
  expect_layer_sizes(tracer.render(small_frame(scene, 1)), 16, 8);
}

TEST(GpuTracer, ReloadChangesTheImageSize) {
  REQUIRE_VULKAN_DEVICE();
  GpuTracer tracer;
  const CompiledScene big = small_scene(16, 8, true);
  const CompiledScene odd = small_scene(13, 5, true); // not a multiple of the tile
  tracer.load(big);
  expect_layer_sizes(tracer.render(small_frame(big, 1)), 16, 8);
  tracer.load(odd);
  expect_layer_sizes(tracer.render(small_frame(odd, 3)), 13, 5);
}

TEST(GpuTracer, RejectsMisuseWithGpuError) {
  REQUIRE_VULKAN_DEVICE();
  GpuTracer tracer;
  const CompiledScene scene = small_scene(16, 8, true);
  EXPECT_THROW(static_cast<void>(tracer.render(small_frame(scene, 1))), GpuError)
      << "render before load";
  tracer.load(scene);
  EXPECT_THROW(static_cast<void>(tracer.render(small_frame(small_scene(8, 8, true), 1))), GpuError)
      << "frame size differs from the loaded scene";
  EXPECT_THROW(static_cast<void>(tracer.render(small_frame(scene, 0))), GpuError) << "zero samples";
  CompiledScene bad_plate = scene;
  bad_plate.plate.pop_back();
  EXPECT_THROW(tracer.load(bad_plate), GpuError);
}

} // namespace
} // namespace camhead::renderer
