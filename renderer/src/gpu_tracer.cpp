// The Vulkan compute tracer: device choice, scene upload, the batched sample
// loop and the read-back of the layers.
//
// Thread safety: a GpuTracer is used by one thread at a time.
#include "camhead/renderer/gpu_tracer.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <functional>
#include <optional>
#include <span>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/bvh.h"
#include "resolve_spv.h"
#include "trace_spv.h"
#include "vulkan_context.h"

namespace camhead::renderer {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Samples per pixel of the next trace submission, from the measured cost of
// the previous one. Submissions of about kTargetSeconds stay well clear of
// display-driver watchdogs (about 2 s) and report progress often, while the
// per-submission overhead stays negligible.
class BatchSizer {
public:
  static constexpr double kTargetSeconds = 0.25;

  [[nodiscard]] std::uint32_t next() const { return samples_; }

  void measured(std::uint32_t samples, double seconds) {
    const double per_sample = std::max(seconds, 1e-6) / samples;
    // Shrinking is immediate; growth is at most 4x per batch, so one cheap
    // batch (or a noisy clock) cannot leap into a watchdog timeout.
    const double ideal = kTargetSeconds / per_sample;
    const double most = std::min(4.0 * samples, 1e9); // stays a valid uint32
    samples_ = static_cast<std::uint32_t>(std::clamp(ideal, 1.0, most));
  }

private:
  std::uint32_t samples_ = 1;
};

std::array<VkDescriptorType, BINDING_COUNT> binding_types() {
  std::array<VkDescriptorType, BINDING_COUNT> types{};
  types.fill(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  types[BINDING_FRAME] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  return types;
}

bool contains_ignoring_case(std::string_view text, std::string_view part) {
  const auto lower = [](char c) { return std::tolower(static_cast<unsigned char>(c)); };
  return std::search(text.begin(), text.end(), part.begin(), part.end(),
                     [&](char a, char b) { return lower(a) == lower(b); }) != text.end();
}

std::vector<GpuDeviceInfo> infos(const std::vector<vk::PhysicalDevice> &devices) {
  std::vector<GpuDeviceInfo> out;
  for (const vk::PhysicalDevice &device : devices)
    out.push_back(device.info);
  return out;
}

// The device rule of GpuTracer's constructor (gpu_tracer.h).
vk::PhysicalDevice choose_device(const std::vector<vk::PhysicalDevice> &devices,
                                 const std::string &wanted) {
  if (devices.empty())
    throw GpuError("no Vulkan device with compute support (install a GPU driver, or Mesa's "
                   "lavapipe from mesa-vulkan-drivers)");
  if (wanted.empty()) {
    for (const vk::PhysicalDevice &device : devices)
      if (!device.quirks.software_device &&
          (device.info.type == "discrete" || device.info.type == "integrated"))
        return device;
    return devices.front();
  }
  const std::string listing = "; available devices:\n" + format_gpu_devices(infos(devices));
  if (std::all_of(wanted.begin(), wanted.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    const std::size_t index = wanted.size() < 9 ? std::stoul(wanted) : devices.size();
    if (index >= devices.size())
      throw GpuError("no Vulkan device with index " + wanted + listing);
    return devices[index];
  }
  for (const vk::PhysicalDevice &device : devices)
    if (contains_ignoring_case(device.info.name, wanted))
      return device;
  throw GpuError("no Vulkan device matches '" + wanted + "'" + listing);
}

template <typename T> std::span<const std::byte> bytes_of(const std::vector<T> &values) {
  return std::as_bytes(std::span(values));
}

// One layer of the read-back buffer (a vec4 per pixel) as an Image of
// `channels` channels starting at component `first`; alpha is dropped.
Image unpack(const float *vec4s, int width, int height, int channels, int first) {
  Image image(width, height, channels);
  const std::size_t pixels = image.pixel_count();
  for (std::size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < channels; ++c)
      image.data[i * channels + c] = vec4s[i * 4 + first + c];
  return image;
}

// The per-pixel buffers, in the order the read-back buffer holds the outputs.
constexpr std::array<int, 4> kOutputs = {BINDING_OUT_COMPOSITE, BINDING_OUT_MIXED, BINDING_OUT_REAL,
                                         BINDING_OUT_AUX};
constexpr std::array<int, 3> kAccumulators = {BINDING_ACCUM_MIXED, BINDING_ACCUM_REAL,
                                              BINDING_ACCUM_AUX};

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
  return infos(instance->compute_devices());
}

struct GpuTracer::Impl {
  explicit Impl(const std::string &wanted);
  ~Impl() { device.wait_idle(); }

  void load(const CompiledScene &scene);
  RenderResult render(const gpu::FrameParams &requested, const ProgressFn &progress,
                      LayerSelection layers, const AdaptiveSampling *adaptive);
  // Adds samples [0, end) to the accumulators in batches (clearing them
  // first if `clear`); `report` gets the samples done.
  void trace_batches(gpu::FrameParams &frame, std::uint32_t end, bool clear,
                     const std::function<void(std::uint32_t)> &report);
  // The accumulated aux layer (layout.h), through the read-back buffer.
  std::vector<glm::vec4> read_accum_aux();
  void dispatch(VkCommandBuffer command_buffer, VkPipeline pipeline) const;

  // Declaration order is destruction order in reverse: everything made from
  // the device goes before it, and the device before the instance.
  vk::Instance instance;
  vk::Device device;
  vk::DescriptorSet descriptors;
  vk::UniquePipelineLayout pipeline_layout;
  vk::UniquePipeline trace;
  vk::UniquePipeline resolve;
  vk::CommandRunner commands;
  vk::Buffer frame_uniform;
  std::array<vk::Buffer, BINDING_COUNT> buffers; // by binding; BINDING_FRAME unused
  vk::Buffer readback; // the kOutputs, one after another, then the display image

  bool loaded = false;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  bool has_plate = false;
  gpu::uvec4 counts{};    // primitives, nodes, lights
  glm::vec3 origin{0.0f}; // CompiledScene::origin of the loaded scene
};

GpuTracer::Impl::Impl(const std::string &wanted)
    : device(choose_device(instance.compute_devices(), wanted)),
      descriptors(device, binding_types()),
      pipeline_layout(vk::make_pipeline_layout(device, descriptors.layout())),
      trace(vk::make_compute_pipeline(
          device, {.layout = pipeline_layout.get(), .spirv = trace_spv, .name = "trace.comp"})),
      resolve(vk::make_compute_pipeline(
          device, {.layout = pipeline_layout.get(), .spirv = resolve_spv, .name = "resolve.comp"})),
      commands(device), frame_uniform(device, {.size = sizeof(gpu::FrameParams),
                                               .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                                               .memory = vk::MemoryUse::upload,
                                               .name = "frame parameters"}) {
  descriptors.write(BINDING_FRAME, frame_uniform);
}

void GpuTracer::Impl::load(const CompiledScene &scene) {
  if (scene.width <= 0 || scene.height <= 0)
    throw GpuError("GpuTracer::load: image size " + std::to_string(scene.width) + "x" +
                   std::to_string(scene.height) + " is empty");
  const std::size_t pixels = std::size_t(scene.width) * std::size_t(scene.height);
  if (!scene.plate.empty() && scene.plate.size() != pixels)
    throw GpuError("GpuTracer::load: plate has " + std::to_string(scene.plate.size()) +
                   " pixels, the image " + std::to_string(pixels));
  const VkDeviceSize layer_bytes = pixels * sizeof(gpu::vec4);
  const VkPhysicalDeviceLimits &limits = device.limits();
  if (layer_bytes > limits.maxStorageBufferRange ||
      std::uint32_t(scene.width + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X >
          limits.maxComputeWorkGroupCount[0] ||
      std::uint32_t(scene.height + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y >
          limits.maxComputeWorkGroupCount[1])
    throw GpuError("image " + std::to_string(scene.width) + "x" + std::to_string(scene.height) +
                   " exceeds the storage buffer or dispatch limits of device '" + device.name() +
                   "'");

  loaded = false; // until every buffer below exists
  vk::Uploader uploader(device);
  // Zero-length arrays get one element so that every binding stays valid.
  // Only the material placeholder is ever read (by rays that miss, which
  // take material 0); the light count is zero and an empty BVH's root bounds
  // admit no ray.
  const auto upload = [&](int binding, std::span<const std::byte> data, std::size_t element,
                          const char *name) {
    buffers[binding] = vk::Buffer(
        device, {.size = std::max<VkDeviceSize>(data.size(), element),
                 .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                 .name = name});
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
  upload(BINDING_PLATE, bytes_of(scene.plate), sizeof(gpu::vec4), "plate");
  uploader.flush(commands);

  for (const int binding : kAccumulators)
    buffers[binding] = vk::Buffer(device, {.size = layer_bytes,
                                           .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                                    VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                                    VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                           .name = "accumulator"});
  buffers[BINDING_SAMPLE_COUNTS] = vk::Buffer(
      device, {.size = pixels * sizeof(std::uint32_t),
               .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
               .name = "sample counts"});
  for (const int binding : kOutputs)
    buffers[binding] = vk::Buffer(
        device, {.size = layer_bytes,
                 .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                 .name = "output layer"});
  buffers[BINDING_OUT_DISPLAY] = vk::Buffer(
      device, {.size = pixels * sizeof(std::uint32_t),
               .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
               .name = "display output"});
  readback = vk::Buffer(device, {.size = layer_bytes * kOutputs.size() + pixels * 4,
                                 .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                 .memory = vk::MemoryUse::readback,
                                 .name = "read-back"});
  for (int binding = 0; binding < BINDING_COUNT; ++binding)
    if (binding != BINDING_FRAME)
      descriptors.write(binding, buffers[binding]);

  width = std::uint32_t(scene.width);
  height = std::uint32_t(scene.height);
  has_plate = !scene.plate.empty();
  counts = gpu::uvec4(scene.primitives.size(), scene.nodes.size(), scene.lights.size(), 0);
  origin = scene.origin;
  loaded = true;
}

void GpuTracer::Impl::dispatch(VkCommandBuffer command_buffer, VkPipeline pipeline) const {
  vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
  const VkDescriptorSet set = descriptors.get();
  vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout.get(), 0,
                          1, &set, 0, nullptr);
  vkCmdDispatch(command_buffer, (width + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X,
                (height + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y, 1);
}

RenderResult GpuTracer::Impl::render(const gpu::FrameParams &requested, const ProgressFn &progress,
                                     LayerSelection selection, const AdaptiveSampling *adaptive) {
  const Clock::time_point start = Clock::now();
  if (!loaded)
    throw GpuError("GpuTracer::render() before a successful load()");
  if (requested.image.x != width || requested.image.y != height)
    throw GpuError("frame is " + std::to_string(requested.image.x) + "x" +
                   std::to_string(requested.image.y) + " but the loaded scene is " +
                   std::to_string(width) + "x" + std::to_string(height));
  const std::uint32_t total = requested.sampling.z;
  if (total == 0)
    throw GpuError("frame asks for 0 samples per pixel (sampling.z)");

  // The kernels index the buffers with these, so they come from what load()
  // uploaded: a stale or hand-made FrameParams must not read out of bounds.
  gpu::FrameParams frame = requested;
  frame.cam_position -= gpu::vec4(origin, 0.0f); // into the compiled scene's frame
  frame.image.z = requested.image.z != 0 && has_plate ? 1u : 0u;
  frame.image.w = counts.z;

  FrameTimings timings;
  Clock::time_point phase = Clock::now();
  std::vector<std::uint32_t> shares;
  std::uint64_t rays = std::uint64_t(width) * height * total;
  if (adaptive == nullptr) {
    frame.tracing.y = 0u;
    trace_batches(frame, total, true, [&](std::uint32_t done) {
      if (progress)
        progress(static_cast<int>(done), static_cast<int>(total));
    });
  } else {
    // adaptive.h: a pilot, the budget from what it saw, each pixel's share.
    const std::uint32_t pilot = adaptive_pilot(*adaptive, total);
    const auto report = [&](double done) {
      if (progress)
        progress(static_cast<int>(done), static_cast<int>(total));
    };
    frame.tracing.y = 0u;
    frame.sampling.z = pilot;
    trace_batches(frame, pilot, true, report);
    gpu::FrameParams budget_frame = requested;
    budget_frame.image = frame.image;
    shares = allocate_samples(read_accum_aux(), budget_frame, pilot, *adaptive);
    vk::Uploader uploader(device);
    uploader.upload(buffers[BINDING_SAMPLE_COUNTS], bytes_of(shares));
    uploader.flush(commands);
    const std::uint32_t most = *std::max_element(shares.begin(), shares.end());
    frame.tracing.y = pilot;
    frame.sampling.z = total;
    trace_batches(frame, most - pilot, false, [&](std::uint32_t done) {
      report(pilot + double(done) * (total - pilot) / std::max(most - pilot, 1u));
    });
    rays = 0;
    for (const std::uint32_t n : shares)
      rays += n;
  }
  timings.trace_s = seconds_since(phase);
  phase = Clock::now();

  frame.sampling = gpu::uvec4(0, total, total, requested.sampling.w);
  std::memcpy(frame_uniform.mapped(), &frame, sizeof frame);
  VkCommandBuffer command_buffer = commands.begin();
  dispatch(command_buffer, resolve.get());
  vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                     VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_TRANSFER_READ_BIT);
  const VkDeviceSize layer_bytes = buffers[BINDING_OUT_AUX].size();
  const std::array<bool, kOutputs.size()> wanted = {selection.composite, selection.mixed,
                                                    selection.real, selection.mask_and_depth};
  for (std::size_t i = 0; i < kOutputs.size(); ++i) {
    if (!wanted[i])
      continue;
    const VkBufferCopy region{0, i * layer_bytes, layer_bytes};
    vkCmdCopyBuffer(command_buffer, buffers[kOutputs[i]].get(), readback.get(), 1, &region);
  }
  const VkDeviceSize display_offset = kOutputs.size() * layer_bytes;
  const VkDeviceSize display_bytes = buffers[BINDING_OUT_DISPLAY].size();
  if (selection.display) {
    const VkBufferCopy region{0, display_offset, display_bytes};
    vkCmdCopyBuffer(command_buffer, buffers[BINDING_OUT_DISPLAY].get(), readback.get(), 1, &region);
  }
  vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  commands.submit_and_wait();
  timings.resolve_s = seconds_since(phase);
  phase = Clock::now();

  const auto *mapped = static_cast<const std::uint8_t *>(readback.mapped());
  const auto layer = [&](std::size_t slot) {
    return reinterpret_cast<const float *>(mapped + slot * layer_bytes);
  };
  const int w = static_cast<int>(width);
  const int h = static_cast<int>(height);
  RenderResult result;
  if (selection.composite)
    result.composite = unpack(layer(0), w, h, 3, 0);
  if (selection.mixed)
    result.mixed = unpack(layer(1), w, h, 3, 0);
  if (selection.real)
    result.real = unpack(layer(2), w, h, 3, 0);
  if (selection.mask_and_depth) {
    const float *aux = layer(3);
    result.mask = unpack(aux, w, h, 1, 0);  // out_aux.x
    result.depth = unpack(aux, w, h, 1, 1); // out_aux.y
  }
  if (selection.display) {
    result.display.assign(mapped + display_offset, mapped + display_offset + display_bytes);
  }
  result.camera_rays = rays;
  result.sample_counts = std::move(shares);
  timings.unpack_s = seconds_since(phase);
  result.timings = timings;
  result.seconds = seconds_since(start);
  return result;
}

void GpuTracer::Impl::trace_batches(gpu::FrameParams &frame, std::uint32_t end, bool clear,
                                    const std::function<void(std::uint32_t)> &report) {
  // One uniform buffer suffices because each batch is waited for before the
  // next one rewrites it.
  BatchSizer sizer;
  if (clear && end == 0) {
    VkCommandBuffer command_buffer = commands.begin();
    for (const int binding : kAccumulators)
      vkCmdFillBuffer(command_buffer, buffers[binding].get(), 0, VK_WHOLE_SIZE, 0);
    commands.submit_and_wait();
  }
  for (std::uint32_t done = 0; done < end;) {
    const std::uint32_t batch = std::min(sizer.next(), end - done);
    frame.sampling.x = done;
    frame.sampling.y = done + batch;
    std::memcpy(frame_uniform.mapped(), &frame, sizeof frame);

    VkCommandBuffer command_buffer = commands.begin();
    if (done == 0 && clear) {
      for (const int binding : kAccumulators)
        vkCmdFillBuffer(command_buffer, buffers[binding].get(), 0, VK_WHOLE_SIZE, 0);
      vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    }
    dispatch(command_buffer, trace.get());
    // Orders this batch's accumulation before the next batch or the resolve.
    vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    const Clock::time_point submitted = Clock::now();
    commands.submit_and_wait();
    sizer.measured(batch, seconds_since(submitted));
    done += batch;
    if (report)
      report(done);
  }
}

std::vector<glm::vec4> GpuTracer::Impl::read_accum_aux() {
  const VkDeviceSize layer_bytes = buffers[BINDING_ACCUM_AUX].size();
  VkCommandBuffer command_buffer = commands.begin();
  vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                     VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_TRANSFER_READ_BIT);
  const VkBufferCopy region{0, 0, layer_bytes};
  vkCmdCopyBuffer(command_buffer, buffers[BINDING_ACCUM_AUX].get(), readback.get(), 1, &region);
  vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  commands.submit_and_wait();
  const auto *values = static_cast<const glm::vec4 *>(readback.mapped());
  return std::vector<glm::vec4>(values, values + std::size_t(width) * height);
}

GpuTracer::GpuTracer(const std::string &device) : impl_(std::make_unique<Impl>(device)) {}

GpuTracer::~GpuTracer() = default;

std::string GpuTracer::device_name() const {
  return impl_->device.name();
}

void GpuTracer::load(const CompiledScene &scene) {
  impl_->load(scene);
}

RenderResult GpuTracer::render(const gpu::FrameParams &frame, const ProgressFn &progress,
                               LayerSelection layers) {
  return impl_->render(frame, progress, layers, nullptr);
}

RenderResult GpuTracer::render_adaptive(const gpu::FrameParams &frame,
                                        const AdaptiveSampling &settings,
                                        const ProgressFn &progress, LayerSelection layers) {
  return impl_->render(frame, progress, layers, &settings);
}

} // namespace camhead::renderer
