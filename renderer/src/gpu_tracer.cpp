// The Vulkan compute tracer (gpu_tracer_impl.h says how it is split): the
// device, the scene's upload and the buffers every frame uses, the pipelines
// and their dispatch, the batched sample loop.
#include "camhead/renderer/gpu_tracer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "adaptive_queue_bins_spv.h"
#include "adaptive_queue_fill_spv.h"
#include "adaptive_shares_spv.h"
#include "adaptive_solve_spv.h"
#include "adaptive_weights_spv.h"
#include "camhead/renderer/bvh.h"
#include "gpu_group_lists.h"
#include "gpu_tracer_impl.h"
#include "gpu_video_frames.h"
#include "reconstruct_spv.h"
#include "resolve_spv.h"
#include "trace_spv.h"
#include "video_decode_spv.h"
#include "video_encode_spv.h"

namespace camhead::renderer {

namespace {

std::array<VkDescriptorType, BINDING_COUNT> binding_types() {
  std::array<VkDescriptorType, BINDING_COUNT> types{};
  types.fill(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  types[BINDING_FRAME] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  types[BINDING_VIDEO] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  types[BINDING_PRIMITIVES] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER; // buffers.glsl says why
  types[BINDING_NODES] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  types[BINDING_MATERIALS] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  types[BINDING_LIGHTS] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  types[BINDING_SURFACES] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  types[BINDING_VIDEO_IN] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  types[BINDING_GROUP_LIST] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  for (const int binding : {BINDING_ACCUM_MIXED, BINDING_ACCUM_REAL, BINDING_ACCUM_AUX,
                            BINDING_PLATE, BINDING_OUT_COMPOSITE, BINDING_FILTER_PIXELS,
                            BINDING_FILTER_ROWS_MIXED, BINDING_FILTER_ROWS_REAL})
    types[std::size_t(binding)] = VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER; // read per pixel
  return types;
}

// How a buffer at `binding` is created: its usage for that descriptor type
// and, for a texel buffer, the format of its view: the camera frame's words,
// or 16-byte texels (the scene's structures as integers, layout.h:
// PRIMITIVE_TEXELS and the others; the per-pixel layers as floats).
vk::BufferCreateInfo binding_buffer(int binding, VkDeviceSize size, VkBufferUsageFlags transfers,
                                    const char *name) {
  vk::BufferCreateInfo create{.size = size, .usage = transfers, .name = name};
  switch (binding_types()[std::size_t(binding)]) {
  case VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER:
    create.usage |= VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
    create.texel_format = binding == BINDING_VIDEO_IN || binding == BINDING_GROUP_LIST
                              ? VK_FORMAT_R32_UINT
                              : VK_FORMAT_R32G32B32A32_UINT;
    break;
  case VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER:
    create.usage |= VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT;
    create.texel_format = VK_FORMAT_R32G32B32A32_SFLOAT;
    break;
  default:
    create.usage |= VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    break;
  }
  return create;
}

// The features of kernel.glsl that `scene` can reach (layout.h, KERNEL_*):
// its primitive kinds, material types, textures and light types.
std::uint32_t scene_kernel_features(const CompiledScene &scene) {
  const auto bits = [](float word) { return std::bit_cast<std::uint32_t>(word); };
  std::uint32_t features = 0;
  for (const gpu::Primitive &p : scene.primitives)
    features |= (bits(p.p0.w) >> 24) == PRIM_SPHERE ? KERNEL_SPHERES : KERNEL_TRIANGLES;
  for (const gpu::Material &m : scene.materials) {
    if (bits(m.params.w) == MAT_MIRROR)
      features |= KERNEL_MIRRORS;
    if (bits(m.params.w) == MAT_GLASS)
      features |= KERNEL_GLASS;
    if (bits(m.params.w) == MAT_DIFFUSE && bits(m.params.y) != 0u)
      features |= KERNEL_TEXTURES;
  }
  for (const gpu::Light &l : scene.lights)
    if (bits(l.position.w) == LIGHT_AREA)
      features |= KERNEL_AREA_LIGHTS;
  return features;
}

// ... and those `frame` asks for.
std::uint32_t frame_kernel_features(const gpu::FrameParams &frame) {
  std::uint32_t features =
      frame.tracing.z == SAMPLER_SOBOL ? KERNEL_CAMERA_SOBOL : KERNEL_CAMERA_CMJ;
  if ((frame.tracing.w & TRACING_SKIP_EMPTY_PIXELS) != 0u)
    features |= KERNEL_SKIP_EMPTY_PIXELS;
  if ((frame.tracing.w & TRACING_LENS_MODEL) != 0u)
    features |= KERNEL_LENS_MODEL;
  return features;
}

// Refuses an image whose per-pixel layers or dispatch grid `device` cannot
// hold, naming the limit; past one, the buffers or dispatches would be
// invalid use rather than an error Vulkan reports.
void check_image_limits(const vk::Device &device, int width, int height) {
  const VkPhysicalDeviceLimits &limits = device.limits();
  const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
  const auto refuse = [&](const std::string &what, std::uint64_t allowed, const char *limit) {
    throw GpuError("image " + std::to_string(width) + "x" + std::to_string(height) + " " + what +
                   "; device '" + device.name() + "' allows " + std::to_string(allowed) + " (" +
                   limit + ")");
  };
  if (pixels > limits.maxTexelBufferElements)
    refuse("has " + std::to_string(pixels) + " pixels, a texel each in its layers",
           limits.maxTexelBufferElements, "maxTexelBufferElements");
  if (pixels * sizeof(gpu::vec4) > limits.maxStorageBufferRange)
    refuse("takes " + std::to_string(pixels * sizeof(gpu::vec4)) + " bytes a layer",
           limits.maxStorageBufferRange, "maxStorageBufferRange");
  const std::uint32_t tiles_x = std::uint32_t(width + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X;
  const std::uint32_t tiles_y = std::uint32_t(height + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y;
  if (tiles_x > limits.maxComputeWorkGroupCount[0])
    refuse("is " + std::to_string(tiles_x) + " workgroups wide", limits.maxComputeWorkGroupCount[0],
           "maxComputeWorkGroupCount[0]");
  if (tiles_y > limits.maxComputeWorkGroupCount[1])
    refuse("is " + std::to_string(tiles_y) + " workgroups high", limits.maxComputeWorkGroupCount[1],
           "maxComputeWorkGroupCount[1]");
}

template <typename T> std::span<const std::byte> bytes_of(const std::vector<T> &values) {
  return std::as_bytes(std::span(values));
}

} // namespace

std::string format_gpu_devices(const std::vector<GpuDeviceInfo> &devices) {
  std::string out;
  for (const GpuDeviceInfo &device : devices)
    out += "  " + std::to_string(device.index) + ": " + device.name + " (" + device.type + ")\n";
  return out;
}

std::vector<GpuDeviceInfo> list_gpu_devices() {
  std::optional<vk::Instance> instance;
  try {
    instance.emplace();
  } catch (const vk::VulkanError &e) {
    // The loader's answer when no driver is installed at all: no devices.
    if (e.result() == VK_ERROR_INCOMPATIBLE_DRIVER)
      return {};
    throw;
  }
  return vk::device_infos(instance->compute_devices());
}

GpuTracer::Impl::Impl(const std::string &wanted)
    : device(vk::choose_device(instance.compute_devices(), wanted)),
      descriptors(device, binding_types()),
      pipeline_layout(vk::make_pipeline_layout(device, descriptors.layout())),
      adaptive_solve(vk::make_compute_pipeline(device, {.layout = pipeline_layout.get(),
                                                        .spirv = adaptive_solve_spv,
                                                        .name = "adaptive_solve.comp"})),
      adaptive_queue_bins(vk::make_compute_pipeline(device, {.layout = pipeline_layout.get(),
                                                             .spirv = adaptive_queue_bins_spv,
                                                             .name = "adaptive_queue_bins.comp"})),
      commands(device), frame_uniform(device, {.size = sizeof(gpu::FrameParams),
                                               .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                                               .memory = vk::MemoryUse::upload,
                                               .name = "frame parameters"}),
      video_uniform(device, {.size = sizeof(gpu::VideoFrames),
                             .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                             .memory = vk::MemoryUse::upload,
                             .name = "video frame parameters"}),
      timestamps(device, 4) {
  descriptors.write(BINDING_FRAME, frame_uniform);
  descriptors.write(BINDING_VIDEO, video_uniform);
}

void GpuTracer::Impl::load(const CompiledScene &scene) {
  if (scene.width <= 0 || scene.height <= 0)
    throw GpuError("GpuTracer::load: image size " + std::to_string(scene.width) + "x" +
                   std::to_string(scene.height) + " is empty");
  const std::size_t pixels = std::size_t(scene.width) * std::size_t(scene.height);
  if (!scene.plate.empty() && scene.plate.size() != pixels)
    throw GpuError("GpuTracer::load: plate has " + std::to_string(scene.plate.size()) +
                   " pixels, the image " + std::to_string(pixels));
  check_image_limits(device, scene.width, scene.height);
  if (scene.surfaces.size() > device.limits().maxTexelBufferElements)
    throw GpuError("the scene's textures and their texture coordinates take " +
                   std::to_string(scene.surfaces.size()) + " texels; device '" + device.name() +
                   "' allows " + std::to_string(device.limits().maxTexelBufferElements) +
                   " (maxTexelBufferElements)");
  const VkDeviceSize layer_bytes = pixels * sizeof(gpu::vec4);

  loaded = false; // until every buffer below exists
  vk::Uploader uploader(device);
  // Zero-length arrays get one element so that every binding stays valid.
  // Only the material placeholder is ever read (by rays that miss, which
  // take material 0); the light count is zero and an empty BVH's root bounds
  // admit no ray.
  const auto upload = [&](int binding, std::span<const std::byte> data, std::size_t element,
                          const char *name) {
    const VkDeviceSize size = std::max<VkDeviceSize>(data.size(), element);
    buffers[binding] =
        vk::Buffer(device, binding_buffer(binding, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, name));
    uploader.upload(buffers[binding], data);
  };
  upload(BINDING_PRIMITIVES, bytes_of(scene.primitives), sizeof(gpu::Primitive), "primitives");
  // Traversal starts at nodes[0]; a zeroed placeholder would be an interior
  // node pointing past the buffer, so a scene without nodes gets the empty
  // BVH, whose root admits no ray.
  const std::vector<gpu::BvhNode> nodes = scene.nodes.empty() ? build_bvh({}).nodes : scene.nodes;
  upload(BINDING_NODES, bytes_of(nodes), sizeof(gpu::BvhNode), "BVH nodes");
  upload(BINDING_MATERIALS, bytes_of(scene.materials), sizeof(gpu::Material), "materials");
  upload(BINDING_LIGHTS, bytes_of(scene.lights), sizeof(gpu::Light), "lights");
  upload(BINDING_SURFACES, bytes_of(scene.surfaces), sizeof(glm::uvec4),
         "texture coordinates and textures");
  // Full size even without a plate: a live frame's camera image goes there.
  upload(BINDING_PLATE, bytes_of(scene.plate), layer_bytes, "plate");
  uploader.flush(commands);

  for (const int binding : kAccumulators)
    buffers[binding] = vk::Buffer(
        device, binding_buffer(binding, layer_bytes,
                               VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                               "accumulator"));
  const auto scratch = [&](int binding, VkDeviceSize size, const char *name) {
    buffers[binding] = vk::Buffer(device, {.size = size,
                                           .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                                    VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                                    VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                           .name = name});
  };
  const std::uint32_t tiles = tiles_of(std::uint32_t(scene.width), std::uint32_t(scene.height));
  scratch(BINDING_SAMPLE_COUNTS, pixels * sizeof(std::uint32_t), "sample counts");
  scratch(BINDING_ADAPTIVE_WEIGHTS, pixels * sizeof(float), "adaptive weights");
  scratch(BINDING_ADAPTIVE_HISTOGRAM, 2 * ADAPTIVE_BINS * sizeof(std::uint32_t),
          "adaptive histogram");
  scratch(BINDING_ADAPTIVE_GROUPS, tiles * sizeof(float), "adaptive tile sums");
  scratch(BINDING_ADAPTIVE_SOLUTION, sizeof(gpu::AdaptiveSolution), "adaptive solution");
  scratch(BINDING_SAMPLE_QUEUE, pixels * sizeof(std::uint32_t), "adaptive sample queue");
  buffers[BINDING_QUEUE_BINS] = vk::Buffer(device, {.size = QUEUE_WORDS * sizeof(std::uint32_t),
                                                    .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                                             VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                                             VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                    .name = "adaptive queue bins"});
  for (const int binding : kOutputs)
    buffers[binding] =
        vk::Buffer(device, binding_buffer(binding, layer_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                          "output layer"));
  for (const int binding :
       {BINDING_FILTER_PIXELS, BINDING_FILTER_ROWS_MIXED, BINDING_FILTER_ROWS_REAL})
    buffers[binding] =
        vk::Buffer(device, binding_buffer(binding, layer_bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                          "reconstruction"));
  filter_ready = false;
  buffers[BINDING_OUT_DISPLAY] = vk::Buffer(
      device, {.size = pixels * sizeof(std::uint32_t),
               .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
               .name = "display output"});
  // The camera frame is written by the host straight into memory the kernel
  // reads (no staging copy); the outputs come back through the read-back.
  vk::BufferCreateInfo camera_frame =
      binding_buffer(BINDING_VIDEO_IN, max_video_bytes(pixels), 0, "camera frame");
  camera_frame.memory = vk::MemoryUse::upload;
  buffers[BINDING_VIDEO_IN] = vk::Buffer(device, camera_frame);
  // Written by the host for each frame with a region, like the camera frame.
  const std::uint32_t video_groups =
      ((std::uint32_t(scene.width) + VIDEO_GROUP_X - 1) / VIDEO_GROUP_X) *
      ((std::uint32_t(scene.height) + VIDEO_GROUP_Y - 1) / VIDEO_GROUP_Y);
  vk::BufferCreateInfo group_lists = binding_buffer(
      BINDING_GROUP_LIST, (GROUP_LIST_VIDEO(tiles) + 1 + video_groups) * sizeof(std::uint32_t), 0,
      "group lists");
  group_lists.memory = vk::MemoryUse::upload;
  buffers[BINDING_GROUP_LIST] = vk::Buffer(device, group_lists);
  buffers[BINDING_VIDEO_OUT] = vk::Buffer(
      device, {.size = VIDEO_MAX_OUTPUTS * max_video_bytes(pixels),
               .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
               .name = "video outputs"});
  readback = vk::Buffer(device, {.size = layer_bytes * kOutputs.size() + 2 * pixels * 4 +
                                         sizeof(gpu::AdaptiveSolution) +
                                         VIDEO_MAX_OUTPUTS * max_video_bytes(pixels),
                                 .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                 .memory = vk::MemoryUse::readback,
                                 .name = "read-back"});
  for (int binding = 0; binding < BINDING_COUNT; ++binding)
    if (binding != BINDING_FRAME && binding != BINDING_VIDEO)
      descriptors.write(binding, buffers[binding]);

  ReadbackLayout &r = readback_layout;
  r.layer_bytes = layer_bytes;
  r.display_offset = kOutputs.size() * layer_bytes;
  r.display_bytes = buffers[BINDING_OUT_DISPLAY].size();
  r.counts_offset = r.display_offset + r.display_bytes;
  r.counts_bytes = buffers[BINDING_SAMPLE_COUNTS].size();
  r.solution_offset = r.counts_offset + r.counts_bytes;
  r.video_offset = r.solution_offset + sizeof(gpu::AdaptiveSolution);
  r.video_slot_bytes = max_video_bytes(pixels);

  width = std::uint32_t(scene.width);
  height = std::uint32_t(scene.height);
  has_plate = !scene.plate.empty();
  counts = gpu::uvec4(scene.primitives.size(), scene.nodes.size(), scene.lights.size(), 0);
  origin = scene.origin;
  scene_features = scene_kernel_features(scene);
  // Built now rather than in the first frame: the kernel for the usual
  // frame (CMJ samples, over an influence region: the default of stills and
  // live frames).
  static_cast<void>(pipeline(trace_kernel(gpu::FrameParams{}), true));
  // Room for any frame's region and group lists: a frame allocates nothing.
  frame_region.rects.reserve(tiles);
  group_places.reserve(std::max(tiles, video_groups));
  video_spans.reserve(tiles);
  uniform_sizer = {};
  second_pass_sizer = {};
  loaded = true;
}

VkPipeline GpuTracer::Impl::pipeline(const Kernel &kernel, bool group_list) {
  const Constants constants = {kernel.features, kernel.variant, group_list ? VK_TRUE : VK_FALSE};
  vk::UniquePipeline &pipeline = specialized_pipelines[{kernel.spirv.data(), constants}];
  if (pipeline.get() == VK_NULL_HANDLE)
    pipeline = vk::make_compute_pipeline(device, {.layout = pipeline_layout.get(),
                                                  .spirv = kernel.spirv,
                                                  .name = kernel.name,
                                                  .dispatch_base = true,
                                                  .constants = constants});
  return pipeline.get();
}

GpuTracer::Impl::Kernel GpuTracer::Impl::trace_kernel(const gpu::FrameParams &frame,
                                                      bool from_queue) const {
  return {trace_spv, "trace.comp",
          specialize ? scene_features | frame_kernel_features(frame) : KERNEL_ALL,
          from_queue ? VK_TRUE : VK_FALSE};
}

GpuTracer::Impl::Kernel GpuTracer::Impl::resolve_kernel(std::uint32_t layers) {
  return {resolve_spv, "resolve.comp", KERNEL_ALL, layers};
}

GpuTracer::Impl::Kernel GpuTracer::Impl::reconstruct_kernel(std::uint32_t pass) {
  return {reconstruct_spv, "reconstruct.comp", KERNEL_ALL, pass};
}

GpuTracer::Impl::Kernel GpuTracer::Impl::decode_kernel(base::PixelFormat format) {
  return {video_decode_spv, "video_decode.comp", KERNEL_ALL, video_format_code(format)};
}

GpuTracer::Impl::Kernel GpuTracer::Impl::encode_kernel(base::PixelFormat format) {
  return {video_encode_spv, "video_encode.comp", KERNEL_ALL, video_format_code(format)};
}

void GpuTracer::Impl::bind(VkCommandBuffer command_buffer, VkPipeline pipeline) const {
  vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
  const VkDescriptorSet set = descriptors.get();
  vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout.get(), 0,
                          1, &set, 0, nullptr);
}

void GpuTracer::Impl::write_group_lists(bool video_groups) {
  auto *words = static_cast<std::uint32_t *>(buffers[BINDING_GROUP_LIST].mapped());
  const auto write = [&](std::uint32_t offset) {
    words[offset] = std::uint32_t(group_places.size());
    std::copy(group_places.begin(), group_places.end(), words + offset + 1);
    return std::uint32_t(group_places.size());
  };
  group_places.clear();
  tile_places(frame_region, group_places);
  tile_list_count = write(GROUP_LIST_TILES);

  video_list_count = 0;
  if (video_groups) {
    group_places.clear();
    video_group_places(frame_region,
                       glm::uvec2((width + VIDEO_GROUP_X - 1) / VIDEO_GROUP_X,
                                  (height + VIDEO_GROUP_Y - 1) / VIDEO_GROUP_Y),
                       video_spans, group_places);
    video_list_count = write(GROUP_LIST_VIDEO(tiles_of(width, height)));
  }
}

void GpuTracer::Impl::dispatch_list(VkCommandBuffer command_buffer, std::uint32_t count,
                                    std::uint32_t base_z) const {
  if (count == 0)
    return;
  // In rows, whose last the kernels cut at the list's end. A GPU schedules
  // workgroups alike whatever the grid's shape, so any row up to the 65535
  // groups every device allows in x would do; a short one puts more than
  // one row, and the cut, under the everyday tests' small frames.
  constexpr std::uint32_t kRow = 16;
  const std::uint32_t row = std::min(count, kRow);
  vkCmdDispatchBase(command_buffer, 0, 0, base_z, row, (count + row - 1) / row, 1);
}

void GpuTracer::Impl::dispatch_region(VkCommandBuffer command_buffer, const Kernel &kernel) {
  if (frame_region.whole_frame()) {
    dispatch(command_buffer, pipeline(kernel));
    return;
  }
  bind(command_buffer, pipeline(kernel, true));
  dispatch_list(command_buffer, tile_list_count);
}

void GpuTracer::Impl::dispatch_video(VkCommandBuffer command_buffer, const Kernel &kernel,
                                     std::uint32_t frame, bool region_only) {
  bind(command_buffer, pipeline(kernel, region_only));
  if (!region_only) {
    vkCmdDispatchBase(command_buffer, 0, 0, frame, (width + VIDEO_GROUP_X - 1) / VIDEO_GROUP_X,
                      (height + VIDEO_GROUP_Y - 1) / VIDEO_GROUP_Y, 1);
    return;
  }
  dispatch_list(command_buffer, video_list_count, frame);
}

void GpuTracer::Impl::dispatch(VkCommandBuffer command_buffer, VkPipeline pipeline,
                               std::optional<glm::uvec2> groups) const {
  bind(command_buffer, pipeline);
  const glm::uvec2 count =
      groups.value_or(glm::uvec2((width + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X,
                                 (height + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y));
  vkCmdDispatch(command_buffer, count.x, count.y, 1);
}

void GpuTracer::Impl::record_clear(VkCommandBuffer command_buffer) const {
  for (const int binding : kAccumulators)
    vkCmdFillBuffer(command_buffer, buffers[binding].get(), 0, VK_WHOLE_SIZE, 0);
  vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

void GpuTracer::Impl::record_allocation(VkCommandBuffer command_buffer) {
  const auto compute_to_compute = [&] {
    vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  };
  timestamps.write(command_buffer, 2, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
  vkCmdFillBuffer(command_buffer, buffers[BINDING_ADAPTIVE_HISTOGRAM].get(), 0, VK_WHOLE_SIZE, 0);
  // Tiles and pixels outside the region keep these zeros.
  vkCmdFillBuffer(command_buffer, buffers[BINDING_ADAPTIVE_GROUPS].get(), 0, VK_WHOLE_SIZE, 0);
  vkCmdFillBuffer(command_buffer, buffers[BINDING_SAMPLE_COUNTS].get(), 0, VK_WHOLE_SIZE, 0);
  vkCmdFillBuffer(command_buffer, buffers[BINDING_QUEUE_BINS].get(), 0,
                  QUEUE_BINS * sizeof(std::uint32_t), 0); // QUEUE_COUNTS
  vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  dispatch_region(command_buffer, {adaptive_weights_spv, "adaptive_weights.comp"});
  compute_to_compute();
  dispatch(command_buffer, adaptive_solve.get(), glm::uvec2(1, 1));
  compute_to_compute();
  dispatch_region(command_buffer, {adaptive_shares_spv, "adaptive_shares.comp"});
  compute_to_compute();
  dispatch(command_buffer, adaptive_queue_bins.get(), glm::uvec2(1, 1));
  compute_to_compute();
  dispatch_region(command_buffer, {adaptive_queue_fill_spv, "adaptive_queue_fill.comp"});
  // The queue and its dispatches, for every batch of the second pass.
  vk::memory_barrier(
      command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
  timestamps.write(command_buffer, 3, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
}

void GpuTracer::Impl::record_queue_batch(VkCommandBuffer command_buffer,
                                         const gpu::FrameParams &frame) {
  bind(command_buffer, pipeline(trace_kernel(frame, true)));
  const std::uint32_t bin =
      QUEUE_BIN(frame.sampling.x + 1u, frame.tracing.y, std::uint32_t(frame.adaptive.y));
  vk::dispatch_indirect(device, command_buffer, buffers[BINDING_QUEUE_BINS].get(),
                        (QUEUE_DISPATCH + 4u * bin) * sizeof(std::uint32_t));
}

int GpuTracer::Impl::trace_batches(gpu::FrameParams &frame, std::uint32_t first, std::uint32_t end,
                                   BatchSizer &sizer, Recorder trace, Recorder prologue,
                                   Recorder epilogue, FunctionRef<void(std::uint32_t)> report) {
  // One uniform buffer suffices because each batch is waited for before the
  // next one rewrites it.
  int submissions = 0;
  std::uint32_t done = first;
  const std::uint32_t most = device.quirks().max_samples_per_dispatch;
  do {
    std::uint32_t batch = std::min(sizer.next(), end - done);
    if (most > 0)
      batch = std::min(batch, most);
    frame.sampling.x = done;
    frame.sampling.y = done + batch;
    std::memcpy(frame_uniform.mapped(), &frame, sizeof frame);

    VkCommandBuffer command_buffer = commands.begin();
    if (done == first && prologue)
      prologue(command_buffer);
    if (batch > 0) {
      trace(command_buffer);
      // Orders this batch's accumulation before the next batch or the resolve.
      vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    }
    if (done + batch == end && epilogue)
      epilogue(command_buffer);
    const GpuClock::time_point submitted = GpuClock::now();
    commands.submit_and_wait();
    ++submissions;
    // A batch that carries the frame's set-up or resolve looks a little
    // dearer per sample than it is: the next batch comes out a little smaller.
    // One over an empty region (a plate-only frame, the virtual objects out
    // of view) traced nothing and says nothing of a sample's cost.
    if (batch > 0 && frame_region.pixels() > 0)
      sizer.measured(batch, seconds_since(submitted));
    done += batch;
    if (report && batch > 0)
      report(done);
  } while (done < end);
  return submissions;
}

void GpuTracer::Impl::prepare_video(const gpu::FrameParams &frame,
                                    std::optional<base::PixelFormat> plate,
                                    std::span<const base::PixelFormat> outputs, bool adaptive) {
  if (!loaded)
    throw GpuError("GpuTracer::prepare_video() before a successful load()");
  const bool reconstructs = frame.reconstruct.x > 0.0f;
  for (const bool group_list : {false, true}) {
    static_cast<void>(pipeline(trace_kernel(frame), group_list));
    static_cast<void>(pipeline(resolve_kernel(RESOLVE_COMPOSITE), group_list)); // plate-only too
    if (reconstructs) {
      static_cast<void>(pipeline(resolve_kernel(RESOLVE_COMPOSITE | RESOLVE_FILTERED), group_list));
      for (const std::uint32_t pass : {0u, 1u})
        static_cast<void>(pipeline(reconstruct_kernel(pass), group_list));
    }
    if (plate)
      static_cast<void>(pipeline(decode_kernel(*plate), group_list));
    for (const base::PixelFormat out : outputs)
      static_cast<void>(pipeline(encode_kernel(out), group_list));
    if (adaptive)
      for (const Kernel &kernel : {Kernel{adaptive_weights_spv, "adaptive_weights.comp"},
                                   Kernel{adaptive_shares_spv, "adaptive_shares.comp"},
                                   Kernel{adaptive_queue_fill_spv, "adaptive_queue_fill.comp"}})
        static_cast<void>(pipeline(kernel, group_list));
  }
  if (adaptive)
    static_cast<void>(pipeline(trace_kernel(frame, true)));
}

GpuTracer::GpuTracer(const std::string &device) : impl_(std::make_unique<Impl>(device)) {}

GpuTracer::~GpuTracer() = default;

std::string GpuTracer::device_name() const {
  return impl_->device.name();
}

void GpuTracer::load(const CompiledScene &scene) {
  impl_->load(scene);
}

void GpuTracer::prepare_video(const gpu::FrameParams &frame, std::optional<base::PixelFormat> plate,
                              std::span<const base::PixelFormat> outputs, bool adaptive) {
  impl_->prepare_video(frame, plate, outputs, adaptive);
}

void GpuTracer::set_kernel_specialization(bool on) {
  impl_->specialize = on;
}

RenderResult GpuTracer::render(const gpu::FrameParams &frame, const ProgressFn &progress,
                               LayerSelection layers, const InfluenceRegion *region) {
  return impl_->render(frame, progress, layers, nullptr, region);
}

RenderResult GpuTracer::render_video(const gpu::FrameParams &frame, const VideoFrame &plate,
                                     std::span<const VideoBuffer> outputs,
                                     const AdaptiveSampling *adaptive,
                                     const InfluenceRegion *region,
                                     std::optional<SampleRange> samples, bool composite) {
  const VideoJob job{plate, outputs, samples.value_or(SampleRange{0, frame.sampling.z})};
  return impl_->render(frame, {}, LayerSelection{composite, false, false, false, false, false},
                       adaptive, region, &job);
}

RenderResult GpuTracer::render_adaptive(const gpu::FrameParams &frame,
                                        const AdaptiveSampling &settings,
                                        const ProgressFn &progress, LayerSelection layers,
                                        const InfluenceRegion *region) {
  return impl_->render(frame, progress, layers, &settings, region);
}

} // namespace camhead::renderer
