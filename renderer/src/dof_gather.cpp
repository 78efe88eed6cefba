// The image-space depth-of-field baseline on the GPU: upload of a pinhole
// render's layers, the gather kernel (dof_gather.comp) and the read-back.
#include "camhead/renderer/dof_gather.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <vector>

#include "dof_gather_spv.h"
#include "vulkan_context.h"

namespace camhead::renderer {

namespace {

// dof_gather.comp's bindings and its uniform block.
enum Binding : std::uint32_t {
  kParams,
  kInMixed,
  kInReal,
  kPlate,
  kOutComposite,
  kOutMixed,
  kOutReal,
  kBindingCount
};
constexpr int kTile = 8;

struct GatherParams {
  glm::vec4 lens;   // aperture radius, focus depth, focal px, max radius px
  glm::uvec4 image; // width, height, has_plate, 0
  glm::vec4 depth;  // x: depth tolerance
};
static_assert(sizeof(GatherParams) == 48);

std::array<VkDescriptorType, kBindingCount> binding_types() {
  std::array<VkDescriptorType, kBindingCount> types{};
  types.fill(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  types[kParams] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  return types;
}

void require_layer(const Image &image, int width, int height, int channels, const char *name) {
  if (image.width != width || image.height != height || image.channels != channels)
    throw GpuError(std::string("DofGather::apply: the pinhole render's ") + name + " layer is " +
                   std::to_string(image.width) + "x" + std::to_string(image.height) + "x" +
                   std::to_string(image.channels) + ", expected " + std::to_string(width) + "x" +
                   std::to_string(height) + "x" + std::to_string(channels));
}

} // namespace

float coc_radius_px(const gpu::FrameParams &lens, float depth) {
  const float z = depth > 0.0f ? depth : 1e30f;
  const float c = 2.0f * lens.lens.x * lens.lens.z * std::abs(z - lens.lens.y) / (z * lens.lens.y);
  return 0.5f * c;
}

struct DofGather::Impl {
  explicit Impl(const std::string &wanted)
      : device(vk::choose_device(instance.compute_devices(), wanted)),
        descriptors(device, binding_types()),
        pipeline_layout(vk::make_pipeline_layout(device, descriptors.layout())),
        gather(vk::make_compute_pipeline(
            device,
            {.layout = pipeline_layout.get(), .spirv = dof_gather_spv, .name = "dof_gather.comp"})),
        commands(device), params(device, {.size = sizeof(GatherParams),
                                          .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                                          .memory = vk::MemoryUse::upload,
                                          .name = "gather parameters"}),
        timestamps(device, 2) {
    descriptors.write(kParams, params);
  }
  ~Impl() { device.wait_idle(); }

  void allocate(std::size_t pixels);
  DofGatherResult apply(const RenderResult &pinhole, const gpu::FrameParams &lens,
                        std::span<const glm::vec4> plate, const DofGatherSettings &settings);

  vk::Instance instance;
  vk::Device device;
  vk::DescriptorSet descriptors;
  vk::UniquePipelineLayout pipeline_layout;
  vk::UniquePipeline gather;
  vk::CommandRunner commands;
  vk::Buffer params;
  vk::TimestampQueries timestamps;
  std::array<vk::Buffer, kBindingCount> buffers; // by binding; kParams unused
  vk::Buffer readback;                           // composite, mixed, real
  std::size_t allocated_pixels = 0;
};

void DofGather::Impl::allocate(std::size_t pixels) {
  if (pixels == allocated_pixels)
    return;
  const VkDeviceSize bytes = pixels * sizeof(glm::vec4);
  for (const Binding binding : {kInMixed, kInReal, kPlate})
    buffers[binding] = vk::Buffer(
        device, {.size = bytes,
                 .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                 .name = "gather input"});
  for (const Binding binding : {kOutComposite, kOutMixed, kOutReal})
    buffers[binding] = vk::Buffer(
        device, {.size = bytes,
                 .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                 .name = "gather output"});
  readback = vk::Buffer(device, {.size = 3 * bytes,
                                 .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                 .memory = vk::MemoryUse::readback,
                                 .name = "gather read-back"});
  for (std::uint32_t binding = kInMixed; binding < kBindingCount; ++binding)
    descriptors.write(binding, buffers[binding]);
  allocated_pixels = pixels;
}

DofGatherResult DofGather::Impl::apply(const RenderResult &pinhole, const gpu::FrameParams &lens,
                                       std::span<const glm::vec4> plate,
                                       const DofGatherSettings &settings) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  const int width = pinhole.mixed.width;
  const int height = pinhole.mixed.height;
  if (width <= 0 || height <= 0)
    throw GpuError("DofGather::apply: the pinhole render has no mixed layer");
  require_layer(pinhole.mixed, width, height, 3, "mixed");
  require_layer(pinhole.real, width, height, 3, "real");
  require_layer(pinhole.mask, width, height, 1, "mask");
  require_layer(pinhole.depth, width, height, 1, "depth");
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  if (!plate.empty() && plate.size() != pixels)
    throw GpuError("DofGather::apply: plate has " + std::to_string(plate.size()) +
                   " pixels, the image " + std::to_string(pixels));
  if (!(lens.lens.y > 0.0f) || !(lens.lens.z > 0.0f) || !(lens.lens.x >= 0.0f))
    throw GpuError("DofGather::apply: the lens needs an aperture radius >= 0, a focus depth > 0 "
                   "and a focal length > 0");

  float max_radius = settings.max_radius_px;
  if (max_radius <= 0.0f) {
    max_radius = 0.5f;
    for (float z : pinhole.depth.data)
      max_radius = std::max(max_radius, coc_radius_px(lens, z));
  }
  max_radius = std::clamp(max_radius, 0.5f, 256.0f);
  // dof_gather.comp visits (2 reach + 1)^2 neighbours and 2 reach + 1 rows;
  // a device that stops a shader's loops after so many iterations would
  // gather part of the window, silently: the reach stays within them, and
  // the result says which it was.
  if (const std::uint32_t most = device.quirks().max_loop_iterations; most > 0) {
    // The widest window side s with s^2 + s <= most (255 on llvmpipe: 127).
    const double side = std::floor((std::sqrt(1.0 + 4.0 * double(most)) - 1.0) / 2.0);
    max_radius = std::min(max_radius, float(std::floor((side - 1.0) / 2.0)));
  }

  allocate(pixels);
  std::vector<glm::vec4> mixed(pixels), real(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    const float *m = &pinhole.mixed.data[i * 3];
    const float *r = &pinhole.real.data[i * 3];
    mixed[i] = glm::vec4(m[0], m[1], m[2], pinhole.mask.data[i]);
    real[i] = glm::vec4(r[0], r[1], r[2], pinhole.depth.data[i]);
  }
  vk::Uploader uploader(device);
  uploader.upload(buffers[kInMixed], std::as_bytes(std::span(mixed)));
  uploader.upload(buffers[kInReal], std::as_bytes(std::span(real)));
  if (!plate.empty())
    uploader.upload(buffers[kPlate], std::as_bytes(plate));
  uploader.flush(commands);

  const GatherParams gp{glm::vec4(lens.lens.x, lens.lens.y, lens.lens.z, max_radius),
                        glm::uvec4(width, height, plate.empty() ? 0u : 1u, 0u),
                        glm::vec4(settings.depth_tolerance, 0.0f, 0.0f, 0.0f)};
  std::memcpy(params.mapped(), &gp, sizeof gp);

  // The kernel alone, timed as the tracer times its batches.
  VkCommandBuffer command_buffer = commands.begin();
  timestamps.reset(command_buffer);
  timestamps.write(command_buffer, 0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
  vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, gather.get());
  const VkDescriptorSet set = descriptors.get();
  vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout.get(), 0,
                          1, &set, 0, nullptr);
  vkCmdDispatch(command_buffer, std::uint32_t(width + kTile - 1) / kTile,
                std::uint32_t(height + kTile - 1) / kTile, 1);
  timestamps.write(command_buffer, 1, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  const Clock::time_point submitted = Clock::now();
  commands.submit_and_wait();
  DofGatherResult result;
  result.gather_s = std::chrono::duration<double>(Clock::now() - submitted).count();
  result.device_s = timestamps.seconds(0, 1).value_or(0.0);
  result.max_radius_px = max_radius;

  command_buffer = commands.begin();
  vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                     VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_TRANSFER_READ_BIT);
  const VkDeviceSize bytes = pixels * sizeof(glm::vec4);
  const std::array<Binding, 3> outputs = {kOutComposite, kOutMixed, kOutReal};
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const VkBufferCopy region{0, k * bytes, bytes};
    vkCmdCopyBuffer(command_buffer, buffers[outputs[k]].get(), readback.get(), 1, &region);
  }
  vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  commands.submit_and_wait();

  const auto *mapped = static_cast<const float *>(readback.mapped());
  result.image.composite = vk::unpack_layer(mapped, width, height, 3, 0);
  result.image.mixed = vk::unpack_layer(mapped + 4 * pixels, width, height, 3, 0);
  result.image.mask = vk::unpack_layer(mapped + 4 * pixels, width, height, 1, 3);
  result.image.real = vk::unpack_layer(mapped + 8 * pixels, width, height, 3, 0);
  result.image.depth = pinhole.depth;
  result.image.camera_rays = pinhole.camera_rays;
  result.image.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

DofGather::DofGather(const std::string &device) : impl_(std::make_unique<Impl>(device)) {}

DofGather::~DofGather() = default;

std::string DofGather::device_name() const {
  return impl_->device.name();
}

DofGatherResult DofGather::apply(const RenderResult &pinhole, const gpu::FrameParams &lens,
                                 std::span<const glm::vec4> plate,
                                 const DofGatherSettings &settings) {
  return impl_->apply(pinhole, lens, plate, settings);
}

} // namespace camhead::renderer
