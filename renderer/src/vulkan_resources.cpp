// Buffers, uploads, command submission, descriptors and compute pipelines.
#include <array>
#include <cstring>
#include <string>
#include <vector>

#include "vulkan_context.h"

namespace camhead::renderer::vk {

namespace {

std::string describe(const char *call, const char *object, VkDeviceSize size) {
  return std::string(call) + " (" + object + ", " + std::to_string(size) + " bytes)";
}

// Refuses a layout of `types` that a compute shader of `device` may not see
// at once (a small GPU allows as few as 4 storage images), naming the limit:
// past it, creating the pipeline layout is invalid use, not an error code.
void check_per_stage_limits(const Device &device, std::span<const VkDescriptorType> types) {
  const VkPhysicalDeviceLimits &limits = device.limits();
  struct Kind {
    const char *what;
    const char *limit;
    std::uint32_t allowed;
    std::uint32_t used = 0;
  };
  std::array<Kind, 4> kinds = {{
      {"storage buffers", "maxPerStageDescriptorStorageBuffers",
       limits.maxPerStageDescriptorStorageBuffers},
      {"uniform buffers", "maxPerStageDescriptorUniformBuffers",
       limits.maxPerStageDescriptorUniformBuffers},
      {"uniform texel buffers", "maxPerStageDescriptorSampledImages",
       limits.maxPerStageDescriptorSampledImages},
      {"storage texel buffers", "maxPerStageDescriptorStorageImages",
       limits.maxPerStageDescriptorStorageImages},
  }};
  for (const VkDescriptorType type : types)
    switch (type) {
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER:
      ++kinds[0].used;
      break;
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER:
      ++kinds[1].used;
      break;
    case VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER:
      ++kinds[2].used;
      break;
    case VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER:
      ++kinds[3].used;
      break;
    default:
      throw GpuError("descriptor type " + std::to_string(int(type)) + " is not one camhead uses");
    }
  for (const Kind &kind : kinds)
    if (kind.used > kind.allowed)
      throw GpuError("the kernels bind " + std::to_string(kind.used) + " " + kind.what +
                     "; device '" + device.name() + "' allows " + std::to_string(kind.allowed) +
                     " (" + kind.limit + ")");
  if (types.size() > limits.maxPerStageResources)
    throw GpuError("the kernels bind " + std::to_string(types.size()) + " resources; device '" +
                   device.name() + "' allows " + std::to_string(limits.maxPerStageResources) +
                   " (maxPerStageResources)");
}

// Bytes per texel of the texel-buffer views camhead makes.
VkDeviceSize texel_bytes(VkFormat format) {
  switch (format) {
  case VK_FORMAT_R32_UINT:
    return 4;
  case VK_FORMAT_R32G32B32A32_UINT:
  case VK_FORMAT_R32G32B32A32_SFLOAT:
    return 16;
  default:
    throw GpuError("texel format " + std::to_string(int(format)) + " is not one camhead uses");
  }
}

} // namespace

// ---------------------------------------------------------------------------
// Buffer

Buffer::Buffer(const Device &device, const BufferCreateInfo &info) : size_(info.size) {
  if (info.size == 0)
    throw GpuError(std::string("zero-size Vulkan buffer '") + info.name + "'");
  if (info.texel_format != VK_FORMAT_UNDEFINED) {
    const VkDeviceSize texels = info.size / texel_bytes(info.texel_format);
    if (texels > device.limits().maxTexelBufferElements)
      throw GpuError(std::string("the ") + info.name + " take " + std::to_string(texels) +
                     " texels; device '" + device.name() + "' allows " +
                     std::to_string(device.limits().maxTexelBufferElements) +
                     " in a texel buffer (maxTexelBufferElements)");
  }

  VkBufferCreateInfo create{};
  create.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  create.size = info.size;
  create.usage = info.usage;
  create.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer buffer = VK_NULL_HANDLE;
  device.check(vkCreateBuffer(device.get(), &create, nullptr, &buffer),
               describe("vkCreateBuffer", info.name, info.size));
  buffer_ = UniqueBuffer(device.get(), buffer);

  VkMemoryRequirements requirements{};
  vkGetBufferMemoryRequirements(device.get(), buffer, &requirements);
  const std::uint32_t type = device.memory_type(requirements.memoryTypeBits, info.memory);
  VkMemoryAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = type;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  device.check(vkAllocateMemory(device.get(), &allocate, nullptr, &memory),
               describe("vkAllocateMemory", info.name, requirements.size));
  memory_ = UniqueMemory(device.get(), memory);
  device.check(vkBindBufferMemory(device.get(), buffer, memory, 0),
               describe("vkBindBufferMemory", info.name, info.size));

  if (device.mappable(type))
    device.check(vkMapMemory(device.get(), memory, 0, VK_WHOLE_SIZE, 0, &mapped_),
                 describe("vkMapMemory", info.name, info.size));

  if (info.texel_format != VK_FORMAT_UNDEFINED) {
    VkBufferViewCreateInfo view_create{};
    view_create.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
    view_create.buffer = buffer;
    view_create.format = info.texel_format;
    view_create.offset = 0;
    view_create.range = VK_WHOLE_SIZE;
    VkBufferView view = VK_NULL_HANDLE;
    device.check(vkCreateBufferView(device.get(), &view_create, nullptr, &view),
                 describe("vkCreateBufferView", info.name, info.size));
    view_ = UniqueBufferView(device.get(), view);
  }
}

// ---------------------------------------------------------------------------
// CommandRunner

CommandRunner::CommandRunner(const Device &device) : device_(&device) {
  VkCommandPoolCreateInfo pool_create{};
  pool_create.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pool_create.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_create.queueFamilyIndex = device.queue_family();
  VkCommandPool pool = VK_NULL_HANDLE;
  device.check(vkCreateCommandPool(device.get(), &pool_create, nullptr, &pool),
               "vkCreateCommandPool");
  pool_ = UniqueCommandPool(device.get(), pool);

  VkCommandBufferAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  allocate.commandPool = pool;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  device.check(vkAllocateCommandBuffers(device.get(), &allocate, &command_buffer_),
               "vkAllocateCommandBuffers");

  VkFenceCreateInfo fence_create{};
  fence_create.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  VkFence fence = VK_NULL_HANDLE;
  device.check(vkCreateFence(device.get(), &fence_create, nullptr, &fence), "vkCreateFence");
  fence_ = UniqueFence(device.get(), fence);
}

VkCommandBuffer CommandRunner::begin() {
  device_->check(vkResetCommandBuffer(command_buffer_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin_info{};
  begin_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin_info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  device_->check(vkBeginCommandBuffer(command_buffer_, &begin_info), "vkBeginCommandBuffer");
  return command_buffer_;
}

void CommandRunner::submit_and_wait() {
  device_->check(vkEndCommandBuffer(command_buffer_), "vkEndCommandBuffer");
  VkFence fence = fence_.get();
  device_->check(vkResetFences(device_->get(), 1, &fence), "vkResetFences");
  VkSubmitInfo submit{};
  submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &command_buffer_;
  device_->check(vkQueueSubmit(device_->queue(), 1, &submit, fence), "vkQueueSubmit");
  // No timeout of our own: a hung GPU is reported by the driver's watchdog
  // as VK_ERROR_DEVICE_LOST, and a slow software device is merely slow.
  device_->check(vkWaitForFences(device_->get(), 1, &fence, VK_TRUE, UINT64_MAX),
                 "vkWaitForFences");
}

// ---------------------------------------------------------------------------
// TimestampQueries

TimestampQueries::TimestampQueries(const Device &device, std::uint32_t count)
    : device_(&device), count_(count) {
  if (device.timestamp_bits() == 0 || count == 0)
    return;
  VkQueryPoolCreateInfo create{};
  create.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  create.queryType = VK_QUERY_TYPE_TIMESTAMP;
  create.queryCount = count;
  VkQueryPool pool = VK_NULL_HANDLE;
  device.check(vkCreateQueryPool(device.get(), &create, nullptr, &pool), "vkCreateQueryPool");
  pool_ = UniqueQueryPool(device.get(), pool);
}

void TimestampQueries::reset(VkCommandBuffer command_buffer) const {
  if (supported())
    vkCmdResetQueryPool(command_buffer, pool_.get(), 0, count_);
}

void TimestampQueries::write(VkCommandBuffer command_buffer, std::uint32_t index,
                             VkPipelineStageFlagBits stage) const {
  if (supported())
    vkCmdWriteTimestamp(command_buffer, stage, pool_.get(), index);
}

std::optional<double> TimestampQueries::seconds(std::uint32_t from, std::uint32_t to) const {
  if (!supported())
    return std::nullopt;
  std::array<std::uint64_t, 2> ticks{};
  for (int k = 0; k < 2; ++k)
    device_->check(vkGetQueryPoolResults(device_->get(), pool_.get(), k == 0 ? from : to, 1,
                                         sizeof(std::uint64_t), &ticks[k], sizeof(std::uint64_t),
                                         VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                   "vkGetQueryPoolResults");
  const std::uint32_t bits = device_->timestamp_bits();
  const std::uint64_t mask = bits >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << bits) - 1;
  const std::uint64_t elapsed = (ticks[1] - ticks[0]) & mask; // survives one wrap
  return double(elapsed) * double(device_->limits().timestampPeriod) * 1e-9;
}

// ---------------------------------------------------------------------------
// Uploader

void Uploader::upload(const Buffer &destination, std::span<const std::byte> data) {
  if (data.size() > destination.size())
    throw GpuError("upload of " + std::to_string(data.size()) + " bytes into a buffer of " +
                   std::to_string(destination.size()));
  if (data.empty())
    return;
  if (destination.mapped() != nullptr) {
    std::memcpy(destination.mapped(), data.data(), data.size());
    return;
  }
  Buffer staging(*device_, {.size = data.size(),
                            .usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                            .memory = MemoryUse::upload,
                            .name = "staging"});
  std::memcpy(staging.mapped(), data.data(), data.size());
  pending_.push_back({std::move(staging), destination.get()});
}

void Uploader::flush(CommandRunner &commands) {
  if (pending_.empty())
    return;
  VkCommandBuffer command_buffer = commands.begin();
  for (const Copy &copy : pending_) {
    const VkBufferCopy region{0, 0, copy.staging.size()};
    vkCmdCopyBuffer(command_buffer, copy.staging.get(), copy.destination, 1, &region);
  }
  memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  commands.submit_and_wait();
  pending_.clear();
}

// ---------------------------------------------------------------------------
// DescriptorSet

DescriptorSet::DescriptorSet(const Device &device, std::span<const VkDescriptorType> types)
    : device_(&device), types_(types.begin(), types.end()) {
  check_per_stage_limits(device, types);
  std::vector<VkDescriptorSetLayoutBinding> bindings;
  std::vector<VkDescriptorPoolSize> pool_sizes;
  for (std::uint32_t binding = 0; binding < types_.size(); ++binding) {
    const VkDescriptorType type = types_[binding];
    bindings.push_back({binding, type, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    bool counted = false;
    for (VkDescriptorPoolSize &size : pool_sizes)
      if (size.type == type) {
        ++size.descriptorCount;
        counted = true;
      }
    if (!counted)
      pool_sizes.push_back({type, 1});
  }

  VkDescriptorSetLayoutCreateInfo layout_create{};
  layout_create.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  layout_create.bindingCount = static_cast<std::uint32_t>(bindings.size());
  layout_create.pBindings = bindings.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  device.check(vkCreateDescriptorSetLayout(device.get(), &layout_create, nullptr, &layout),
               "vkCreateDescriptorSetLayout");
  layout_ = UniqueDescriptorSetLayout(device.get(), layout);

  VkDescriptorPoolCreateInfo pool_create{};
  pool_create.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  pool_create.maxSets = 1;
  pool_create.poolSizeCount = static_cast<std::uint32_t>(pool_sizes.size());
  pool_create.pPoolSizes = pool_sizes.data();
  VkDescriptorPool pool = VK_NULL_HANDLE;
  device.check(vkCreateDescriptorPool(device.get(), &pool_create, nullptr, &pool),
               "vkCreateDescriptorPool");
  pool_ = UniqueDescriptorPool(device.get(), pool);

  VkDescriptorSetAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  allocate.descriptorPool = pool;
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = &layout;
  device.check(vkAllocateDescriptorSets(device.get(), &allocate, &set_),
               "vkAllocateDescriptorSets");
}

void DescriptorSet::write(std::uint32_t binding, const Buffer &buffer) {
  const VkDescriptorBufferInfo buffer_info{buffer.get(), 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet write{};
  write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
  write.dstSet = set_;
  write.dstBinding = binding;
  write.descriptorCount = 1;
  write.descriptorType = types_.at(binding);
  const VkBufferView view = buffer.view();
  if (write.descriptorType == VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER ||
      write.descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER) {
    if (view == VK_NULL_HANDLE)
      throw GpuError("descriptor binding " + std::to_string(binding) +
                     " is a texel buffer, but the buffer has no texel view");
    write.pTexelBufferView = &view;
  } else {
    write.pBufferInfo = &buffer_info;
  }
  vkUpdateDescriptorSets(device_->get(), 1, &write, 0, nullptr);
}

// ---------------------------------------------------------------------------
// Pipelines

UniquePipelineLayout make_pipeline_layout(const Device &device, VkDescriptorSetLayout set_layout) {
  VkPipelineLayoutCreateInfo create{};
  create.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  create.setLayoutCount = 1;
  create.pSetLayouts = &set_layout;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  device.check(vkCreatePipelineLayout(device.get(), &create, nullptr, &layout),
               "vkCreatePipelineLayout");
  return UniquePipelineLayout(device.get(), layout);
}

UniquePipeline make_compute_pipeline(const Device &device, const ComputePipelineCreateInfo &info) {
  const std::string what = std::string(" (") + info.name + ")";
  VkShaderModuleCreateInfo module_create{};
  module_create.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  module_create.codeSize = info.spirv.size_bytes();
  module_create.pCode = info.spirv.data();
  VkShaderModule module = VK_NULL_HANDLE;
  device.check(vkCreateShaderModule(device.get(), &module_create, nullptr, &module),
               "vkCreateShaderModule" + what);
  // The pipeline keeps what it needs; the module can go once it is built.
  const UniqueShaderModule module_owner(device.get(), module);

  VkComputePipelineCreateInfo create{};
  create.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  create.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  create.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  create.stage.module = module;
  create.stage.pName = info.entry;
  std::vector<VkSpecializationMapEntry> entries;
  for (std::uint32_t id = 0; id < info.constants.size(); ++id)
    entries.push_back({id, id * std::uint32_t(sizeof(std::uint32_t)), sizeof(std::uint32_t)});
  VkSpecializationInfo specialization{};
  specialization.mapEntryCount = std::uint32_t(entries.size());
  specialization.pMapEntries = entries.data();
  specialization.dataSize = info.constants.size_bytes();
  specialization.pData = info.constants.data();
  if (!entries.empty())
    create.stage.pSpecializationInfo = &specialization;
  create.layout = info.layout;
  create.flags = info.dispatch_base ? VK_PIPELINE_CREATE_DISPATCH_BASE_BIT : 0;
  VkPipeline pipeline = VK_NULL_HANDLE;
  device.check(
      vkCreateComputePipelines(device.get(), VK_NULL_HANDLE, 1, &create, nullptr, &pipeline),
      "vkCreateComputePipelines" + what);
  return UniquePipeline(device.get(), pipeline);
}

void memory_barrier(VkCommandBuffer command_buffer, VkPipelineStageFlags src_stage,
                    VkAccessFlags src_access, VkPipelineStageFlags dst_stage,
                    VkAccessFlags dst_access) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = src_access;
  barrier.dstAccessMask = dst_access;
  vkCmdPipelineBarrier(command_buffer, src_stage, dst_stage, 0, 1, &barrier, 0, nullptr, 0,
                       nullptr);
}

void dispatch_indirect(const Device &device, VkCommandBuffer command_buffer, VkBuffer buffer,
                       VkDeviceSize offset) {
  if (device.quirks().indirect_dispatch_keeps_base)
    vkCmdDispatchBase(command_buffer, 0, 0, 0, 0, 0, 0); // no workgroups; the base back at 0
  vkCmdDispatchIndirect(command_buffer, buffer, offset);
}

} // namespace camhead::renderer::vk
