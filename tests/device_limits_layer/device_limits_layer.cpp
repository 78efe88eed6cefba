// A Vulkan layer for tests: the device underneath, with the limits that
// CAMHEAD_TEST_DEVICE_LIMITS names lowered, for example
//
//   CAMHEAD_TEST_DEVICE_LIMITS=maxPerStageDescriptorStorageImages=4
//
// and, with CAMHEAD_TEST_DEVICE_TYPE=integrated, reported as a hardware
// GPU. So what camhead does on a smaller GPU than the one at hand (refuse,
// naming the limit, or fall back) is tested through the real driver and the
// real loader, not through a fake device. Only the properties a program
// reads change; the driver is not told, so a program that ignores a lowered
// limit still runs, and the test sees that it did.
//
// Enabled by the environment, never by camhead: VK_LAYER_PATH=<this folder
// in the build tree> VK_INSTANCE_LAYERS=VK_LAYER_CAMHEAD_device_limits
// (tests/CMakeLists.txt, cli.small_device_*).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <vulkan/vk_layer.h>
#include <vulkan/vulkan.h>

namespace {

// The loader puts its dispatch table pointer first in every dispatchable
// handle; an instance and its physical devices share one.
using DispatchKey = void *;
template <typename Handle> DispatchKey key_of(Handle handle) {
  return *reinterpret_cast<DispatchKey *>(handle);
}

struct InstanceNext {
  PFN_vkGetInstanceProcAddr get_proc_addr = nullptr;
  PFN_vkDestroyInstance destroy = nullptr;
  PFN_vkGetPhysicalDeviceProperties properties = nullptr;
  PFN_vkGetPhysicalDeviceProperties2 properties2 = nullptr;
  PFN_vkGetPhysicalDeviceProperties2KHR properties2_khr = nullptr;
};

std::mutex mutex;
std::map<DispatchKey, InstanceNext> instances;
std::map<DispatchKey, PFN_vkGetDeviceProcAddr> devices;

InstanceNext next_of(DispatchKey key) {
  const std::lock_guard lock(mutex);
  const auto it = instances.find(key);
  if (it == instances.end()) {
    std::fprintf(stderr, "VK_LAYER_CAMHEAD_device_limits: a handle of no instance it saw\n");
    std::abort();
  }
  return it->second;
}

// The VkPhysicalDeviceLimits fields a test may lower (camhead checks these).
const std::map<std::string_view, std::uint32_t VkPhysicalDeviceLimits::*> &limit_fields() {
  static const std::map<std::string_view, std::uint32_t VkPhysicalDeviceLimits::*> fields = {
      {"maxPerStageDescriptorStorageBuffers",
       &VkPhysicalDeviceLimits::maxPerStageDescriptorStorageBuffers},
      {"maxPerStageDescriptorUniformBuffers",
       &VkPhysicalDeviceLimits::maxPerStageDescriptorUniformBuffers},
      {"maxPerStageDescriptorSampledImages",
       &VkPhysicalDeviceLimits::maxPerStageDescriptorSampledImages},
      {"maxPerStageDescriptorStorageImages",
       &VkPhysicalDeviceLimits::maxPerStageDescriptorStorageImages},
      {"maxPerStageResources", &VkPhysicalDeviceLimits::maxPerStageResources},
      {"maxTexelBufferElements", &VkPhysicalDeviceLimits::maxTexelBufferElements},
      {"maxStorageBufferRange", &VkPhysicalDeviceLimits::maxStorageBufferRange},
  };
  return fields;
}

// "name=value,name=value"; a name it does not know or a value that is not a
// number stops the program: a test whose limit went unapplied would pass
// for the wrong reason.
std::vector<std::pair<std::uint32_t VkPhysicalDeviceLimits::*, std::uint32_t>> lowered_limits() {
  std::vector<std::pair<std::uint32_t VkPhysicalDeviceLimits::*, std::uint32_t>> lowered;
  const char *spec = std::getenv("CAMHEAD_TEST_DEVICE_LIMITS");
  std::string_view rest = spec != nullptr ? spec : "";
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    const std::size_t equals = item.find('=');
    const auto field = limit_fields().find(item.substr(0, equals));
    char *end = nullptr;
    const std::string value(equals == std::string_view::npos ? "" : item.substr(equals + 1));
    const unsigned long number = std::strtoul(value.c_str(), &end, 10);
    if (field == limit_fields().end() || value.empty() || *end != '\0' || number > UINT32_MAX) {
      std::fprintf(stderr,
                   "VK_LAYER_CAMHEAD_device_limits: CAMHEAD_TEST_DEVICE_LIMITS: '%.*s' is not "
                   "name=number with a limit this layer lowers\n",
                   int(item.size()), item.data());
      std::abort();
    }
    lowered.emplace_back(field->second, std::uint32_t(number));
  }
  return lowered;
}

// CAMHEAD_TEST_DEVICE_TYPE=integrated|discrete: lavapipe passed off as a
// hardware GPU, for what camhead chooses on a machine with one.
std::optional<VkPhysicalDeviceType> device_type() {
  const char *type = std::getenv("CAMHEAD_TEST_DEVICE_TYPE");
  if (type == nullptr)
    return std::nullopt;
  if (std::strcmp(type, "integrated") == 0)
    return VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU;
  if (std::strcmp(type, "discrete") == 0)
    return VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU;
  std::fprintf(stderr,
               "VK_LAYER_CAMHEAD_device_limits: CAMHEAD_TEST_DEVICE_TYPE: '%s' is not "
               "integrated or discrete\n",
               type);
  std::abort();
}

void lower(VkPhysicalDeviceProperties &properties) {
  static const auto lowered = lowered_limits();
  static const auto type = device_type();
  for (const auto &[field, value] : lowered)
    if (value < properties.limits.*field)
      properties.limits.*field = value;
  if (type)
    properties.deviceType = *type;
}

VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceProperties(VkPhysicalDevice physical,
                                                       VkPhysicalDeviceProperties *properties) {
  next_of(key_of(physical)).properties(physical, properties);
  lower(*properties);
}

VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceProperties2(VkPhysicalDevice physical,
                                                        VkPhysicalDeviceProperties2 *properties) {
  next_of(key_of(physical)).properties2(physical, properties);
  lower(properties->properties);
}

VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceProperties2KHR(
    VkPhysicalDevice physical, VkPhysicalDeviceProperties2 *properties) {
  next_of(key_of(physical)).properties2_khr(physical, properties);
  lower(properties->properties);
}

template <typename Info, typename Structure> Info *link_info(const void *next, Structure type) {
  for (auto *info = static_cast<Info *>(const_cast<void *>(next)); info != nullptr;
       info = static_cast<Info *>(const_cast<void *>(info->pNext)))
    if (info->sType == type && info->function == VK_LAYER_LINK_INFO)
      return info;
  return nullptr;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateInstance(const VkInstanceCreateInfo *create,
                                              const VkAllocationCallbacks *allocator,
                                              VkInstance *instance) {
  auto *link = link_info<VkLayerInstanceCreateInfo>(create->pNext,
                                                    VK_STRUCTURE_TYPE_LOADER_INSTANCE_CREATE_INFO);
  if (link == nullptr)
    return VK_ERROR_INITIALIZATION_FAILED;
  const PFN_vkGetInstanceProcAddr next = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  link->u.pLayerInfo = link->u.pLayerInfo->pNext; // the next layer's link, for it
  const auto create_next =
      reinterpret_cast<PFN_vkCreateInstance>(next(VK_NULL_HANDLE, "vkCreateInstance"));
  const VkResult result = create_next(create, allocator, instance);
  if (result != VK_SUCCESS)
    return result;
  InstanceNext functions;
  functions.get_proc_addr = next;
  const auto get = [&](const char *name) { return next(*instance, name); };
  functions.destroy = reinterpret_cast<PFN_vkDestroyInstance>(get("vkDestroyInstance"));
  functions.properties =
      reinterpret_cast<PFN_vkGetPhysicalDeviceProperties>(get("vkGetPhysicalDeviceProperties"));
  functions.properties2 =
      reinterpret_cast<PFN_vkGetPhysicalDeviceProperties2>(get("vkGetPhysicalDeviceProperties2"));
  functions.properties2_khr = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties2KHR>(
      get("vkGetPhysicalDeviceProperties2KHR"));
  const std::lock_guard lock(mutex);
  instances[key_of(*instance)] = functions;
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL DestroyInstance(VkInstance instance,
                                           const VkAllocationCallbacks *allocator) {
  const DispatchKey key = key_of(instance);
  const PFN_vkDestroyInstance destroy = next_of(key).destroy;
  {
    const std::lock_guard lock(mutex);
    instances.erase(key);
  }
  destroy(instance, allocator);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateDevice(VkPhysicalDevice physical,
                                            const VkDeviceCreateInfo *create,
                                            const VkAllocationCallbacks *allocator,
                                            VkDevice *device) {
  auto *link = link_info<VkLayerDeviceCreateInfo>(create->pNext,
                                                  VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO);
  if (link == nullptr)
    return VK_ERROR_INITIALIZATION_FAILED;
  const PFN_vkGetInstanceProcAddr next_instance = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  const PFN_vkGetDeviceProcAddr next_device = link->u.pLayerInfo->pfnNextGetDeviceProcAddr;
  link->u.pLayerInfo = link->u.pLayerInfo->pNext;
  const auto create_next =
      reinterpret_cast<PFN_vkCreateDevice>(next_instance(VK_NULL_HANDLE, "vkCreateDevice"));
  const VkResult result = create_next(physical, create, allocator, device);
  if (result != VK_SUCCESS)
    return result;
  const std::lock_guard lock(mutex);
  devices[key_of(*device)] = next_device;
  return VK_SUCCESS;
}

PFN_vkGetDeviceProcAddr next_device_proc_addr(VkDevice device) {
  const std::lock_guard lock(mutex);
  const auto it = devices.find(key_of(device));
  return it == devices.end() ? nullptr : it->second;
}

VKAPI_ATTR void VKAPI_CALL DestroyDevice(VkDevice device, const VkAllocationCallbacks *allocator) {
  const DispatchKey key = key_of(device);
  const auto destroy = reinterpret_cast<PFN_vkDestroyDevice>(
      next_device_proc_addr(device)(device, "vkDestroyDevice"));
  {
    const std::lock_guard lock(mutex);
    devices.erase(key);
  }
  destroy(device, allocator);
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice device, const char *name);

// This layer's own entry points, by name; every other call goes straight on.
PFN_vkVoidFunction own(std::string_view name) {
  static const std::map<std::string_view, PFN_vkVoidFunction> functions = {
      {"vkCreateInstance", reinterpret_cast<PFN_vkVoidFunction>(&CreateInstance)},
      {"vkDestroyInstance", reinterpret_cast<PFN_vkVoidFunction>(&DestroyInstance)},
      {"vkCreateDevice", reinterpret_cast<PFN_vkVoidFunction>(&CreateDevice)},
      {"vkDestroyDevice", reinterpret_cast<PFN_vkVoidFunction>(&DestroyDevice)},
      {"vkGetDeviceProcAddr", reinterpret_cast<PFN_vkVoidFunction>(&GetDeviceProcAddr)},
      {"vkGetPhysicalDeviceProperties",
       reinterpret_cast<PFN_vkVoidFunction>(&GetPhysicalDeviceProperties)},
      {"vkGetPhysicalDeviceProperties2",
       reinterpret_cast<PFN_vkVoidFunction>(&GetPhysicalDeviceProperties2)},
      {"vkGetPhysicalDeviceProperties2KHR",
       reinterpret_cast<PFN_vkVoidFunction>(&GetPhysicalDeviceProperties2KHR)},
  };
  const auto it = functions.find(name);
  return it == functions.end() ? nullptr : it->second;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetInstanceProcAddr(VkInstance instance, const char *name);

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice device, const char *name) {
  if (name == std::string_view("vkGetDeviceProcAddr") ||
      name == std::string_view("vkDestroyDevice"))
    return own(name);
  const PFN_vkGetDeviceProcAddr next = next_device_proc_addr(device);
  return next != nullptr ? next(device, name) : nullptr;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetInstanceProcAddr(VkInstance instance,
                                                             const char *name) {
  if (name == std::string_view("vkGetInstanceProcAddr"))
    return reinterpret_cast<PFN_vkVoidFunction>(&GetInstanceProcAddr);
  if (const PFN_vkVoidFunction function = own(name))
    return function;
  if (instance == VK_NULL_HANDLE)
    return nullptr;
  return next_of(key_of(instance)).get_proc_addr(instance, name);
}

} // namespace

extern "C" VKAPI_ATTR VkResult VKAPI_CALL
vkNegotiateLoaderLayerInterfaceVersion(VkNegotiateLayerInterface *version) {
  if (version == nullptr || version->sType != LAYER_NEGOTIATE_INTERFACE_STRUCT)
    return VK_ERROR_INITIALIZATION_FAILED;
  if (version->loaderLayerInterfaceVersion > 2)
    version->loaderLayerInterfaceVersion = 2;
  version->pfnGetInstanceProcAddr = &GetInstanceProcAddr;
  version->pfnGetDeviceProcAddr = &GetDeviceProcAddr;
  version->pfnGetPhysicalDeviceProcAddr = nullptr;
  return VK_SUCCESS;
}
