// camhead's compiled scene as an Embree 3 scene: the triangles as one
// triangle mesh, the spheres as Embree's sphere points (true ray-sphere
// intersection, not discs). Embree types stay in this file and its .cpp.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <embree3/rtcore.h>

#include "camhead/renderer/compiled_scene.h"

namespace camhead::bench {

struct EmbreeDeviceDeleter {
  void operator()(RTCDevice device) const { rtcReleaseDevice(device); }
};
struct EmbreeSceneDeleter {
  void operator()(RTCScene scene) const { rtcReleaseScene(scene); }
};
using EmbreeDevice = std::unique_ptr<RTCDeviceTy, EmbreeDeviceDeleter>;
using EmbreeScene = std::unique_ptr<RTCSceneTy, EmbreeSceneDeleter>;

// geomID of each kind in the scene: primID indexes triangles or spheres of
// camhead's primitive array in order, so hits map back to primitives.
inline constexpr unsigned kTriangleGeometry = 0;
inline constexpr unsigned kSphereGeometry = 1;

struct EmbreeWorld {
  EmbreeDevice device;
  EmbreeScene scene;
  std::vector<unsigned> triangle_prims; // primID -> index into CompiledScene::primitives
  std::vector<unsigned> sphere_prims;
  double build_s = 0.0;
};

// Throws std::runtime_error with Embree's error text.
[[nodiscard]] EmbreeWorld make_embree_world(const renderer::CompiledScene &scene,
                                            RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH);

// "Embree 3.13.5, ray16 native, ..." for the report.
[[nodiscard]] std::string describe_embree(RTCDevice device);

} // namespace camhead::bench
