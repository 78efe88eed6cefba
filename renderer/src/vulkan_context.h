// The renderer's one include point for Vulkan: RAII handles created from
// CreateInfo-style structs, error checks that throw GpuError, and the driver
// quirks. Private to the renderer; nothing here may appear in a public header.
//
// Thread safety: none. One thread drives a Device and everything made from it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <vulkan/vulkan.h>

#include "camhead/renderer/gpu_devices.h"
#include "camhead/renderer/gpu_error.h"
#include "camhead/renderer/image.h"

namespace camhead::renderer::vk {

// A failed Vulkan call; the message names the call, the VkResult and the device.
class VulkanError : public GpuError {
public:
  VulkanError(const std::string &message, VkResult result) : GpuError(message), result_(result) {}
  [[nodiscard]] VkResult result() const { return result_; }

private:
  VkResult result_;
};

[[nodiscard]] std::string result_name(VkResult result);

// Throws VulkanError "<call> failed: <VkResult> [on <device>]" unless VK_SUCCESS.
void check(VkResult result, std::string_view call, std::string_view device = {});

// Owns one object created from a VkDevice; destroyed with `Destroy`.
template <typename T, void (*Destroy)(VkDevice, T, const VkAllocationCallbacks *)>
class DeviceHandle {
public:
  DeviceHandle() = default;
  DeviceHandle(VkDevice device, T handle) : device_(device), handle_(handle) {}
  ~DeviceHandle() { reset(); }
  DeviceHandle(const DeviceHandle &) = delete;
  DeviceHandle &operator=(const DeviceHandle &) = delete;
  DeviceHandle(DeviceHandle &&other) noexcept
      : device_(other.device_), handle_(std::exchange(other.handle_, VK_NULL_HANDLE)) {}
  DeviceHandle &operator=(DeviceHandle &&other) noexcept {
    if (this != &other) {
      reset();
      device_ = other.device_;
      handle_ = std::exchange(other.handle_, VK_NULL_HANDLE);
    }
    return *this;
  }

  [[nodiscard]] T get() const { return handle_; }
  void reset() {
    if (handle_ != VK_NULL_HANDLE)
      Destroy(device_, std::exchange(handle_, VK_NULL_HANDLE), nullptr);
  }

private:
  VkDevice device_ = VK_NULL_HANDLE;
  T handle_ = VK_NULL_HANDLE;
};

using UniqueBuffer = DeviceHandle<VkBuffer, vkDestroyBuffer>;
using UniqueBufferView = DeviceHandle<VkBufferView, vkDestroyBufferView>;
using UniqueMemory = DeviceHandle<VkDeviceMemory, vkFreeMemory>;
using UniqueDescriptorSetLayout = DeviceHandle<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>;
using UniqueDescriptorPool = DeviceHandle<VkDescriptorPool, vkDestroyDescriptorPool>;
using UniquePipelineLayout = DeviceHandle<VkPipelineLayout, vkDestroyPipelineLayout>;
using UniquePipeline = DeviceHandle<VkPipeline, vkDestroyPipeline>;
using UniqueShaderModule = DeviceHandle<VkShaderModule, vkDestroyShaderModule>;
using UniqueCommandPool = DeviceHandle<VkCommandPool, vkDestroyCommandPool>;
using UniqueFence = DeviceHandle<VkFence, vkDestroyFence>;
using UniqueQueryPool = DeviceHandle<VkQueryPool, vkDestroyQueryPool>;

// Driver-specific decisions, made once per device in the "Driver quirks"
// section of vulkan_context.cpp (with the process-wide ones), so that the rest
// of the code asks a named question instead of testing vendor ids or names.
struct DriverQuirks {
  // Software rasterisers (Mesa lavapipe, SwiftShader) report
  // VK_PHYSICAL_DEVICE_TYPE_CPU; they are the fallback, never the default
  // choice while a real GPU is present.
  bool software_device = false;
  // Mesa lavapipe (22.3) adds the base of the command buffer's last
  // vkCmdDispatchBase to a later vkCmdDispatchIndirect, which has none
  // (lvp_execute.c: handle_dispatch_indirect leaves grid_base as it was).
  // An empty vkCmdDispatchBase at base 0 before it resets that
  // (vk::dispatch_indirect).
  bool indirect_dispatch_keeps_base = false;
  // The most loop iterations a shader invocation may run, all its loops
  // together; 0 for no bound. Mesa's llvmpipe (gallivm, lp_bld_limits.h)
  // stops every loop of an invocation, silently, once they have run
  // LP_MAX_TGSI_LOOP_ITERATIONS (65535) times. The depth-of-field gather's
  // reach comes from it (dof_gather.cpp), and so does:
  std::uint32_t max_loop_iterations = 0;
  // the most samples per pixel one dispatch of the trace kernel may take
  // (0: no bound), else the rest of a pixel's samples are never traced. The
  // demo's paths take 100-350 iterations of the kernel's loops a sample (its
  // adaptive shares lost samples from about 200 on: bench/RESULTS.md,
  // "lavapipe stops a long shader"); a budget of 4000 a sample leaves room
  // for paths ten times as long: 16 samples on llvmpipe.
  std::uint32_t max_samples_per_dispatch = 0;
};

struct PhysicalDevice {
  VkPhysicalDevice handle = VK_NULL_HANDLE;
  GpuDeviceInfo info;
  std::uint32_t compute_family = 0;
  std::uint32_t timestamp_bits = 0; // of the compute queue; 0: no timestamps
  DriverQuirks quirks;
};

// True when the environment asks for the validation layer:
// CAMHEAD_VULKAN_VALIDATION=1.
[[nodiscard]] bool validation_requested();

struct InstanceCreateInfo {
  const char *application = "camhead";
  // Enables VK_LAYER_KHRONOS_validation if it is installed.
  bool validation = validation_requested();
};

class Instance {
public:
  explicit Instance(const InstanceCreateInfo &info = {});
  ~Instance();
  Instance(const Instance &) = delete;
  Instance &operator=(const Instance &) = delete;

  [[nodiscard]] VkInstance get() const { return instance_; }
  // Devices with Vulkan 1.1 and a compute queue, in enumeration order; their
  // info.index is the position in this list.
  [[nodiscard]] std::vector<PhysicalDevice> compute_devices() const;

private:
  VkInstance instance_ = VK_NULL_HANDLE;
};

// The devices' GpuDeviceInfo, in order.
[[nodiscard]] std::vector<GpuDeviceInfo> device_infos(const std::vector<PhysicalDevice> &devices);

// The device rule of GpuTracer's constructor (gpu_tracer.h), shared by every
// user of the GPU so that all find the same one. Throws GpuError naming the
// devices there are.
[[nodiscard]] PhysicalDevice choose_device(const std::vector<PhysicalDevice> &devices,
                                           const std::string &wanted);

// One layer of a read-back buffer (a vec4 per pixel) as an Image of
// `channels` channels starting at component `first`.
[[nodiscard]] Image unpack_layer(const float *vec4s, int width, int height, int channels,
                                 int first);

// Where a buffer lives, which decides the memory type.
enum class MemoryUse {
  device_local, // kernels read and write it; filled by Uploader
  upload,       // host writes, device reads (uniforms, staging)
  readback,     // device writes, host reads
};

class Device {
public:
  // The Instance that listed `physical` must outlive the Device.
  explicit Device(const PhysicalDevice &physical);
  ~Device(); // waits for the device to go idle first
  Device(const Device &) = delete;
  Device &operator=(const Device &) = delete;

  [[nodiscard]] VkDevice get() const { return device_; }
  [[nodiscard]] VkQueue queue() const { return queue_; }
  [[nodiscard]] std::uint32_t queue_family() const { return physical_.compute_family; }
  [[nodiscard]] const std::string &name() const { return physical_.info.name; }
  [[nodiscard]] const DriverQuirks &quirks() const { return physical_.quirks; }
  [[nodiscard]] const VkPhysicalDeviceLimits &limits() const { return properties_.limits; }
  [[nodiscard]] std::uint32_t timestamp_bits() const { return physical_.timestamp_bits; }

  // A memory type allowed by `type_bits` for `use`; throws GpuError if none.
  [[nodiscard]] std::uint32_t memory_type(std::uint32_t type_bits, MemoryUse use) const;
  // Host-visible and coherent: Buffer maps such memory persistently.
  [[nodiscard]] bool mappable(std::uint32_t memory_type) const;

  // check() with this device's name in the message.
  void check(VkResult result, std::string_view call) const;
  void wait_idle() const noexcept;

private:
  PhysicalDevice physical_;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
};

struct BufferCreateInfo {
  VkDeviceSize size = 0;
  VkBufferUsageFlags usage = 0;
  MemoryUse memory = MemoryUse::device_local;
  const char *name = "buffer"; // for error messages
  // Set for a texel buffer (usage includes a texel buffer bit): the buffer
  // gets a view of its whole range in this format. More texels than the
  // device's maxTexelBufferElements throw GpuError, naming the buffer.
  VkFormat texel_format = VK_FORMAT_UNDEFINED;
};

// A buffer with its own allocation, persistently mapped when host-visible.
class Buffer {
public:
  Buffer() = default;
  Buffer(const Device &device, const BufferCreateInfo &info);

  [[nodiscard]] VkBuffer get() const { return buffer_.get(); }
  [[nodiscard]] VkDeviceSize size() const { return size_; }
  [[nodiscard]] void *mapped() const { return mapped_; }          // null unless host-visible
  [[nodiscard]] VkBufferView view() const { return view_.get(); } // null unless texel_format

private:
  UniqueMemory memory_; // declared first: the buffer goes before its memory
  UniqueBuffer buffer_;
  UniqueBufferView view_; // and its view before it
  VkDeviceSize size_ = 0;
  void *mapped_ = nullptr;
};

// One primary command buffer with its pool and fence: record, submit, wait.
class CommandRunner {
public:
  explicit CommandRunner(const Device &device);

  // Resets the command buffer and begins recording.
  [[nodiscard]] VkCommandBuffer begin();
  // Ends, submits and blocks until the device has executed it.
  void submit_and_wait();

private:
  const Device *device_;
  UniqueCommandPool pool_;
  VkCommandBuffer command_buffer_ = VK_NULL_HANDLE; // freed with the pool
  UniqueFence fence_;
};

// Timestamps written by the device into a query pool: how long work took on
// the device itself, without the submission latency that a host clock around
// it includes (bench/RESULTS.md: most of a frame under 3 ms on an H100).
class TimestampQueries {
public:
  TimestampQueries(const Device &device, std::uint32_t count);

  // False where the compute queue has no timestamps; the other calls are
  // then no-ops and seconds() is empty.
  [[nodiscard]] bool supported() const { return pool_.get() != VK_NULL_HANDLE; }
  // Records the reset of every query; must precede their writes.
  void reset(VkCommandBuffer command_buffer) const;
  // Records query `index`: the time when all earlier commands finished
  // `stage` (top of pipe: when the next ones start).
  void write(VkCommandBuffer command_buffer, std::uint32_t index,
             VkPipelineStageFlagBits stage) const;
  // Seconds from query `from` to query `to`, both executed.
  [[nodiscard]] std::optional<double> seconds(std::uint32_t from, std::uint32_t to) const;

private:
  const Device *device_;
  UniqueQueryPool pool_;
  std::uint32_t count_ = 0;
};

// Fills device-local buffers: through the mapping where the memory is
// host-visible, else through staging buffers copied in one submission.
class Uploader {
public:
  explicit Uploader(const Device &device) : device_(&device) {}
  void upload(const Buffer &destination, std::span<const std::byte> data);
  // Records the pending copies, waits for them and frees the staging buffers.
  void flush(CommandRunner &commands);

private:
  struct Copy {
    Buffer staging;
    VkBuffer destination;
  };
  const Device *device_;
  std::vector<Copy> pending_;
};

// One descriptor set layout and a pool holding one set of it; binding i of
// the set has descriptor type types[i], one descriptor each.
class DescriptorSet {
public:
  DescriptorSet(const Device &device, std::span<const VkDescriptorType> types);

  [[nodiscard]] VkDescriptorSetLayout layout() const { return layout_.get(); }
  [[nodiscard]] VkDescriptorSet get() const { return set_; }
  // Points `binding` at the whole of `buffer`, through its view for a
  // texel buffer binding. The set must not be in use.
  void write(std::uint32_t binding, const Buffer &buffer);

private:
  const Device *device_;
  std::vector<VkDescriptorType> types_;
  UniqueDescriptorSetLayout layout_;
  UniqueDescriptorPool pool_;
  VkDescriptorSet set_ = VK_NULL_HANDLE; // freed with the pool
};

[[nodiscard]] UniquePipelineLayout make_pipeline_layout(const Device &device,
                                                        VkDescriptorSetLayout set_layout);

struct ComputePipelineCreateInfo {
  VkPipelineLayout layout = VK_NULL_HANDLE;
  std::span<const std::uint32_t> spirv;
  const char *entry = "main";
  const char *name = "kernel"; // for error messages
  // Dispatched with vkCmdDispatchBase (a part of the grid).
  bool dispatch_base = false;
  // Specialization constant i (32 bits each, constant_id i) = constants[i].
  std::span<const std::uint32_t> constants = {};
};

[[nodiscard]] UniquePipeline make_compute_pipeline(const Device &device,
                                                   const ComputePipelineCreateInfo &info);

// A global memory barrier: everything `src_access` wrote in `src_stage` is
// visible to `dst_access` in `dst_stage`.
void memory_barrier(VkCommandBuffer command_buffer, VkPipelineStageFlags src_stage,
                    VkAccessFlags src_access, VkPipelineStageFlags dst_stage,
                    VkAccessFlags dst_access);

// vkCmdDispatchIndirect of the bound pipeline with the VkDispatchIndirectCommand
// at `offset` in `buffer`, on every driver as the specification says
// (DriverQuirks::indirect_dispatch_keeps_base).
void dispatch_indirect(const Device &device, VkCommandBuffer command_buffer, VkBuffer buffer,
                       VkDeviceSize offset);

} // namespace camhead::renderer::vk
