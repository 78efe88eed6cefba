// Errors, driver quirks, the instance, device discovery and the logical device.
#include "vulkan_context.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include <dlfcn.h>

namespace camhead::renderer::vk {

namespace {

constexpr const char *kValidationLayer = "VK_LAYER_KHRONOS_validation";

const char *device_type_name(VkPhysicalDeviceType type) {
  switch (type) {
  case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
    return "discrete";
  case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
    return "integrated";
  case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
    return "virtual";
  case VK_PHYSICAL_DEVICE_TYPE_CPU:
    return "cpu";
  default:
    return "other";
  }
}

bool layer_available(const char *name) {
  std::uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS)
    return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) < VK_SUCCESS)
    return false;
  layers.resize(count);
  for (const VkLayerProperties &layer : layers)
    if (std::strcmp(layer.layerName, name) == 0)
      return true;
  return false;
}

// ---------------------------------------------------------------------------
// Driver quirks: the one place that knows about particular drivers.

DriverQuirks detect_quirks(const VkPhysicalDeviceProperties &properties) {
  DriverQuirks quirks;
  // Mesa lavapipe ("llvmpipe (LLVM ...)") and SwiftShader run the kernels on
  // the host CPU and say so through the device type.
  quirks.software_device = properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  const bool llvmpipe = std::string_view(properties.deviceName).starts_with("llvmpipe");
  quirks.indirect_dispatch_keeps_base = llvmpipe;
  quirks.max_loop_iterations = llvmpipe ? 65535u : 0u;
  constexpr std::uint32_t kLoopIterationsPerSample = 4000; // DriverQuirks
  quirks.max_samples_per_dispatch = quirks.max_loop_iterations / kLoopIterationsPerSample;
  return quirks;
}

// Mesa's lavapipe makes a small allocation each time the loader loads it and
// loses it when vkDestroyInstance unloads it again, so LeakSanitizer reports
// 128 bytes per instance. Keeping the library resident for the life of the
// process (RTLD_NODELETE) makes that memory reachable and spares each new
// instance the driver's start-up. RTLD_NOLOAD: only if the loader loaded it.
void keep_software_drivers_loaded() {
  static_cast<void>(dlopen("libvulkan_lvp.so", RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE));
}

} // namespace

std::string result_name(VkResult result) {
  switch (result) {
#define CAMHEAD_VK_RESULT_CASE(name)                                                               \
  case name:                                                                                       \
    return #name;
    CAMHEAD_VK_RESULT_CASE(VK_SUCCESS)
    CAMHEAD_VK_RESULT_CASE(VK_NOT_READY)
    CAMHEAD_VK_RESULT_CASE(VK_TIMEOUT)
    CAMHEAD_VK_RESULT_CASE(VK_INCOMPLETE)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_INITIALIZATION_FAILED)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_DEVICE_LOST)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_FRAGMENTED_POOL)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_UNKNOWN)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_FRAGMENTATION)
    CAMHEAD_VK_RESULT_CASE(VK_ERROR_INVALID_SHADER_NV)
#undef CAMHEAD_VK_RESULT_CASE
  default:
    return "VkResult(" + std::to_string(static_cast<int>(result)) + ")";
  }
}

void check(VkResult result, std::string_view call, std::string_view device) {
  if (result == VK_SUCCESS)
    return;
  std::string message = std::string(call) + " failed: " + result_name(result);
  if (!device.empty())
    message += " on device '" + std::string(device) + "'";
  throw VulkanError(message, result);
}

bool validation_requested() {
  const char *value = std::getenv("CAMHEAD_VULKAN_VALIDATION");
  return value != nullptr && std::strcmp(value, "1") == 0;
}

// ---------------------------------------------------------------------------
// Instance

Instance::Instance(const InstanceCreateInfo &info) {
  std::vector<const char *> layers;
  if (info.validation) {
    if (layer_available(kValidationLayer)) {
      layers.push_back(kValidationLayer);
    } else {
      // Asked for explicitly, so silence would hide why no messages appear.
      std::fprintf(stderr, "camhead: CAMHEAD_VULKAN_VALIDATION=1 but %s is not installed\n",
                   kValidationLayer);
    }
  }

  VkApplicationInfo application{};
  application.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  application.pApplicationName = info.application;
  application.pEngineName = "camhead";
  application.apiVersion = VK_API_VERSION_1_1;

  VkInstanceCreateInfo create{};
  create.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  create.pApplicationInfo = &application;
  create.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  create.ppEnabledLayerNames = layers.data();
  check(vkCreateInstance(&create, nullptr, &instance_), "vkCreateInstance");
  keep_software_drivers_loaded();
}

Instance::~Instance() {
  if (instance_ != VK_NULL_HANDLE)
    vkDestroyInstance(instance_, nullptr);
}

std::vector<PhysicalDevice> Instance::compute_devices() const {
  std::uint32_t count = 0;
  check(vkEnumeratePhysicalDevices(instance_, &count, nullptr), "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> handles(count);
  const VkResult listed = vkEnumeratePhysicalDevices(instance_, &count, handles.data());
  if (listed != VK_INCOMPLETE) // a device unplugged in between is not an error
    check(listed, "vkEnumeratePhysicalDevices");
  handles.resize(count);

  std::vector<PhysicalDevice> devices;
  for (VkPhysicalDevice handle : handles) {
    VkPhysicalDeviceProperties properties{};
    vkGetPhysicalDeviceProperties(handle, &properties);
    if (properties.apiVersion < VK_API_VERSION_1_1)
      continue;

    std::uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(handle, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    vkGetPhysicalDeviceQueueFamilyProperties(handle, &family_count, families.data());
    for (std::uint32_t family = 0; family < family_count; ++family) {
      if ((families[family].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0)
        continue;
      PhysicalDevice device;
      device.handle = handle;
      device.info.index = static_cast<int>(devices.size());
      device.info.name = properties.deviceName;
      device.info.type = device_type_name(properties.deviceType);
      device.compute_family = family;
      device.timestamp_bits = families[family].timestampValidBits;
      device.quirks = detect_quirks(properties);
      devices.push_back(std::move(device));
      break;
    }
  }
  return devices;
}

// ---------------------------------------------------------------------------
// Device

Device::Device(const PhysicalDevice &physical) : physical_(physical) {
  vkGetPhysicalDeviceProperties(physical.handle, &properties_);
  vkGetPhysicalDeviceMemoryProperties(physical.handle, &memory_);

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{};
  queue.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  queue.queueFamilyIndex = physical.compute_family;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;

  VkDeviceCreateInfo create{};
  create.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  create.queueCreateInfoCount = 1;
  create.pQueueCreateInfos = &queue;
  check(vkCreateDevice(physical.handle, &create, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, physical.compute_family, 0, &queue_);
}

Device::~Device() {
  if (device_ == VK_NULL_HANDLE)
    return;
  wait_idle();
  vkDestroyDevice(device_, nullptr);
}

std::uint32_t Device::memory_type(std::uint32_t type_bits, MemoryUse use) const {
  VkMemoryPropertyFlags required = 0;
  VkMemoryPropertyFlags preferred = 0;
  switch (use) {
  case MemoryUse::device_local:
    required = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    break;
  case MemoryUse::upload:
    required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    break;
  case MemoryUse::readback:
    required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    // Uncached (write-combined) memory makes reading the image back crawl.
    preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
    break;
  }
  // The spec orders memory types best-first, so the first match is the one to take.
  for (const VkMemoryPropertyFlags want : {required | preferred, required}) {
    for (std::uint32_t type = 0; type < memory_.memoryTypeCount; ++type) {
      const VkMemoryPropertyFlags flags = memory_.memoryTypes[type].propertyFlags;
      if ((type_bits & (1u << type)) != 0 && (flags & want) == want)
        return type;
    }
  }
  throw GpuError("no memory type with flags " + std::to_string(required) + " among bits " +
                 std::to_string(type_bits) + " on device '" + name() + "'");
}

bool Device::mappable(std::uint32_t memory_type) const {
  // Coherent memory needs no flush or invalidate, which keeps every mapped
  // access a plain memcpy.
  constexpr VkMemoryPropertyFlags wanted =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  return (memory_.memoryTypes[memory_type].propertyFlags & wanted) == wanted;
}

void Device::check(VkResult result, std::string_view call) const {
  vk::check(result, call, name());
}

void Device::wait_idle() const noexcept {
  // Used on teardown paths, where a lost device must not throw again.
  if (device_ != VK_NULL_HANDLE)
    static_cast<void>(vkDeviceWaitIdle(device_));
}

// ---------------------------------------------------------------------------
// Device choice and read-back

namespace {

bool contains_ignoring_case(std::string_view text, std::string_view part) {
  const auto lower = [](char c) { return std::tolower(static_cast<unsigned char>(c)); };
  return std::search(text.begin(), text.end(), part.begin(), part.end(),
                     [&](char a, char b) { return lower(a) == lower(b); }) != text.end();
}

} // namespace

std::vector<GpuDeviceInfo> device_infos(const std::vector<PhysicalDevice> &devices) {
  std::vector<GpuDeviceInfo> out;
  for (const PhysicalDevice &device : devices)
    out.push_back(device.info);
  return out;
}

PhysicalDevice choose_device(const std::vector<PhysicalDevice> &devices,
                             const std::string &wanted) {
  if (devices.empty())
    throw GpuError("no Vulkan device with compute support (install a GPU driver, or Mesa's "
                   "lavapipe from mesa-vulkan-drivers)");
  if (wanted.empty()) {
    for (const PhysicalDevice &device : devices)
      if (!device.quirks.software_device &&
          (device.info.type == "discrete" || device.info.type == "integrated"))
        return device;
    return devices.front();
  }
  const std::string listing = "; available devices:\n" + format_gpu_devices(device_infos(devices));
  if (std::all_of(wanted.begin(), wanted.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    const std::size_t index = wanted.size() < 9 ? std::stoul(wanted) : devices.size();
    if (index >= devices.size())
      throw GpuError("no Vulkan device with index " + wanted + listing);
    return devices[index];
  }
  for (const PhysicalDevice &device : devices)
    if (contains_ignoring_case(device.info.name, wanted))
      return device;
  throw GpuError("no Vulkan device matches '" + wanted + "'" + listing);
}

Image unpack_layer(const float *vec4s, int width, int height, int channels, int first) {
  Image image(width, height, channels);
  const std::size_t pixels = image.pixel_count();
  for (std::size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < channels; ++c)
      image.data[i * channels + c] = vec4s[i * 4 + first + c];
  return image;
}

} // namespace camhead::renderer::vk
