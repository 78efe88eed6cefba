// What the GPU side of the renderer throws: no Vulkan device, a device that
// cannot hold the image, a call out of order, a Vulkan call that failed
// (vulkan_context.h's VulkanError, which carries its VkResult). The message
// names the device, the limit or the call.
#pragma once

#include <stdexcept>

namespace camhead::renderer {

class GpuError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

} // namespace camhead::renderer
