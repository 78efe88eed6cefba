// The Vulkan devices the GPU tracer can run on, for `camhead devices`, for
// choosing one (GpuTracer's constructor) and for the errors that list them.
#pragma once

#include <string>
#include <vector>

namespace camhead::renderer {

struct GpuDeviceInfo {
  int index = 0;
  std::string name;
  std::string type; // "cpu", "discrete", "integrated", "virtual", "other"
};

// Lists the Vulkan devices that can run the tracer (compute queue present).
[[nodiscard]] std::vector<GpuDeviceInfo> list_gpu_devices();

// One line per device, "  <index>: <name> (<type>)", for listings and errors.
[[nodiscard]] std::string format_gpu_devices(const std::vector<GpuDeviceInfo> &devices);

} // namespace camhead::renderer
