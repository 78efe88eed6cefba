#include "embree_scene.h"

#include <chrono>
#include <cstring>
#include <stdexcept>

namespace camhead::bench {
namespace {

using renderer::gpu::Primitive;

unsigned prim_kind(const Primitive &prim) {
  unsigned bits = 0;
  static_assert(sizeof(bits) == sizeof(prim.p0.w));
  std::memcpy(&bits, &prim.p0.w, sizeof(bits));
  return bits >> 24;
}

void check(RTCDevice device, const char *what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE) {
    throw std::runtime_error(std::string("Embree: ") + what + " failed (error " +
                             std::to_string(int(error)) + ")");
  }
}

} // namespace

EmbreeWorld make_embree_world(const renderer::CompiledScene &scene, RTCBuildQuality quality) {
  EmbreeWorld world;
  world.device.reset(rtcNewDevice(nullptr));
  if (!world.device) {
    throw std::runtime_error("Embree: rtcNewDevice failed (error " +
                             std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  }
  RTCDevice device = world.device.get();
  for (unsigned i = 0; i < scene.primitives.size(); ++i) {
    (prim_kind(scene.primitives[i]) == PRIM_SPHERE ? world.sphere_prims : world.triangle_prims)
        .push_back(i);
  }

  const auto start = std::chrono::steady_clock::now();
  world.scene.reset(rtcNewScene(device));
  RTCScene rtc_scene = world.scene.get();
  rtcSetSceneBuildQuality(rtc_scene, quality);

  // Triangles, three vertices each as camhead stores them (v0, v0 + e1,
  // v0 + e2): no shared vertices, the same floats the kernel tests.
  RTCGeometry triangles = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(triangles, quality);
  const std::size_t tri_count = world.triangle_prims.size();
  auto *vertices = static_cast<float *>(rtcSetNewGeometryBuffer(
      triangles, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * tri_count));
  auto *indices = static_cast<unsigned *>(rtcSetNewGeometryBuffer(
      triangles, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), tri_count));
  check(device, "triangle buffers");
  for (std::size_t t = 0; t < tri_count; ++t) {
    const Primitive &prim = scene.primitives[world.triangle_prims[t]];
    const glm::vec3 v0(prim.p0), v1 = v0 + glm::vec3(prim.p1), v2 = v0 + glm::vec3(prim.p2);
    const glm::vec3 corners[3] = {v0, v1, v2};
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 3; ++k) {
        vertices[(3 * t + c) * 3 + k] = corners[c][k];
      }
      indices[3 * t + c] = unsigned(3 * t + c);
    }
  }
  rtcCommitGeometry(triangles);
  rtcAttachGeometryByID(rtc_scene, triangles, kTriangleGeometry);
  rtcReleaseGeometry(triangles);

  // Spheres: x, y, z, radius.
  RTCGeometry spheres = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  const std::size_t sphere_count = world.sphere_prims.size();
  auto *points = static_cast<float *>(rtcSetNewGeometryBuffer(
      spheres, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), sphere_count));
  check(device, "sphere buffer");
  for (std::size_t s = 0; s < sphere_count; ++s) {
    const Primitive &prim = scene.primitives[world.sphere_prims[s]];
    points[4 * s + 0] = prim.p0.x;
    points[4 * s + 1] = prim.p0.y;
    points[4 * s + 2] = prim.p0.z;
    points[4 * s + 3] = prim.p1.x;
  }
  rtcCommitGeometry(spheres);
  rtcAttachGeometryByID(rtc_scene, spheres, kSphereGeometry);
  rtcReleaseGeometry(spheres);

  rtcCommitScene(rtc_scene);
  check(device, "scene build");
  world.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return world;
}

std::string describe_embree(RTCDevice device) {
  std::string text =
      "Embree " + std::to_string(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_MAJOR)) +
      "." + std::to_string(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_MINOR)) + "." +
      std::to_string(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_PATCH));
  const char *tasking[] = {"internal", "TBB", "PPL"};
  const auto task = rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_TASKING_SYSTEM);
  text += std::string(", tasking ") + (task >= 0 && task < 3 ? tasking[task] : "?");
  text += rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)
              ? ", native ray16"
              : ", ray16 emulated";
  return text;
}

} // namespace camhead::bench
