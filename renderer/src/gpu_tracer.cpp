// The Vulkan compute tracer: device choice, scene upload, the batched sample
// loop and the read-back of the layers.
//
// Thread safety: a GpuTracer is used by one thread at a time.
#include "camhead/renderer/gpu_tracer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <vector>

#include "adaptive_queue_bins_spv.h"
#include "adaptive_queue_fill_spv.h"
#include "adaptive_shares_spv.h"
#include "adaptive_solve_spv.h"
#include "adaptive_weights_spv.h"
#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/bvh.h"
#include "frame_checks.h"
#include "function_ref.h"
#include "resolve_spv.h"
#include "trace_spv.h"
#include "video_decode_spv.h"
#include "video_encode_spv.h"
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
// per-submission overhead stays negligible. A sizer lives as long as the
// loaded scene, so that a live frame of a few samples, once one frame has
// been measured, is one submission.
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
  types[BINDING_VIDEO] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  types[BINDING_PRIMITIVES] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER; // buffers.glsl says why
  types[BINDING_NODES] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  types[BINDING_MATERIALS] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  types[BINDING_LIGHTS] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  types[BINDING_VIDEO_IN] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  types[BINDING_GROUP_LIST] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  for (const int binding : {BINDING_ACCUM_MIXED, BINDING_ACCUM_REAL, BINDING_ACCUM_AUX,
                            BINDING_PLATE, BINDING_OUT_COMPOSITE})
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
// its primitive kinds, material types and light types.
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

// The per-pixel buffers, in the order the read-back buffer holds the outputs.
constexpr std::array<int, 4> kOutputs = {BINDING_OUT_COMPOSITE, BINDING_OUT_MIXED, BINDING_OUT_REAL,
                                         BINDING_OUT_AUX};
constexpr std::array<int, 3> kAccumulators = {BINDING_ACCUM_MIXED, BINDING_ACCUM_REAL,
                                              BINDING_ACCUM_AUX};

// The largest frame of any format: 4 bytes per pixel (xrgb8888).
VkDeviceSize max_video_bytes(std::size_t pixels) {
  return VkDeviceSize(4) * pixels;
}

std::uint32_t video_format_code(base::PixelFormat pixel) {
  switch (pixel) {
  case base::PixelFormat::yuyv:
    return VIDEO_YUYV;
  case base::PixelFormat::nv12:
    return VIDEO_NV12;
  case base::PixelFormat::rgb24:
    return VIDEO_RGB24;
  case base::PixelFormat::bgr24:
    return VIDEO_BGR24;
  case base::PixelFormat::xrgb8888:
    return VIDEO_XRGB8888;
  }
  return VIDEO_YUYV;
}

// A frame as the video kernels see it: packed rows starting at `first_word`.
gpu::VideoParams video_params(const base::VideoFormat &f, std::uint32_t first_word) {
  gpu::VideoParams v{};
  v.format = gpu::uvec4(video_format_code(f.pixel), f.matrix == base::ColorMatrix::bt601 ? 0u : 1u,
                        f.range == base::ColorRange::full ? 1u : 0u, first_word);
  v.size = gpu::uvec4(std::uint32_t(f.width), std::uint32_t(f.height),
                      std::uint32_t(base::packed_stride(f.pixel, f.width)), 0u);
  return v;
}

// Rows of `height` (plus NV12's chroma rows) between two strides.
void copy_rows(const std::uint8_t *from, std::size_t from_stride, std::uint8_t *to,
               std::size_t to_stride, const base::VideoFormat &f) {
  const std::size_t row = base::packed_stride(f.pixel, f.width);
  const std::size_t rows =
      std::size_t(f.height) + (f.pixel == base::PixelFormat::nv12 ? std::size_t(f.height) / 2 : 0);
  for (std::size_t y = 0; y < rows; ++y)
    std::memcpy(to + y * to_stride, from + y * from_stride, row);
}

// The bytes of `rects` alone, as copy_rows copies all of them. The rects are
// whole tiles (influence_region.h): even rows and columns, so no 4:2:2 pixel
// pair or 4:2:0 chroma sample straddles an edge.
void copy_rects(const std::uint8_t *from, std::size_t from_stride, std::uint8_t *to,
                std::size_t to_stride, const base::VideoFormat &f,
                std::span<const PixelRect> rects) {
  const std::size_t pixel_bytes = base::packed_stride(f.pixel, 2) / 2; // NV12: its luma
  const std::size_t chroma_row = f.pixel == base::PixelFormat::nv12 ? std::size_t(f.height) : 0;
  const auto copy = [&](std::size_t row, std::size_t x0, std::size_t x1) {
    std::memcpy(to + row * to_stride + x0 * pixel_bytes,
                from + row * from_stride + x0 * pixel_bytes, (x1 - x0) * pixel_bytes);
  };
  for (const PixelRect &rect : rects)
    for (std::uint32_t y = rect.y0; y < rect.y1; ++y) {
      copy(y, rect.x0, rect.x1);
      if (chroma_row != 0 && y % 2 == 0) // a Cb Cr pair per luma pair, a row per two
        copy(chroma_row + y / 2, rect.x0, rect.x1);
    }
}

// The 8x8 tiles of a width x height image.
std::uint32_t tiles_of(std::uint32_t width, std::uint32_t height) {
  return ((width + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X) *
         ((height + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y);
}

// A workgroup's place in a group list (layout.h, BINDING_GROUP_LIST).
std::uint32_t group_place(std::uint32_t x, std::uint32_t y) {
  return y << 16 | x;
}

// The 8x8 tiles of `region`, each once, appended to `places`.
void tile_places(const InfluenceRegion &region, std::vector<std::uint32_t> &places) {
  for (const PixelRect &rect : region.rects)
    for (std::uint32_t ty = rect.y0 / CAMHEAD_TILE_Y;
         ty < (rect.y1 + CAMHEAD_TILE_Y - 1) / CAMHEAD_TILE_Y; ++ty)
      for (std::uint32_t tx = rect.x0 / CAMHEAD_TILE_X;
           tx < (rect.x1 + CAMHEAD_TILE_X - 1) / CAMHEAD_TILE_X; ++tx)
        places.push_back(group_place(tx, ty));
}

// The video kernels' workgroups (VIDEO_GROUP_X x VIDEO_GROUP_Y pixels) that
// `region` touches, each once, appended to `places`; `spans` is scratch.
void video_group_places(const InfluenceRegion &region, glm::uvec2 groups,
                        std::vector<glm::uvec2> &spans, std::vector<std::uint32_t> &places) {
  for (std::uint32_t gy = 0; gy < groups.y; ++gy) {
    spans.clear();
    const std::uint32_t y0 = gy * VIDEO_GROUP_Y;
    for (const PixelRect &rect : region.rects)
      if (rect.y0 < y0 + VIDEO_GROUP_Y && rect.y1 > y0)
        spans.emplace_back(rect.x0 / VIDEO_GROUP_X, (rect.x1 + VIDEO_GROUP_X - 1) / VIDEO_GROUP_X);
    std::sort(spans.begin(), spans.end(), [](glm::uvec2 a, glm::uvec2 b) { return a.x < b.x; });
    std::uint32_t next = 0; // the row's first group not yet listed
    for (const glm::uvec2 span : spans) {
      for (std::uint32_t gx = std::max(span.x, next); gx < span.y; ++gx)
        places.push_back(group_place(gx, gy));
      next = std::max(next, span.y);
    }
  }
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

struct GpuTracer::Impl {
  explicit Impl(const std::string &wanted);
  ~Impl() { device.wait_idle(); }

  void load(const CompiledScene &scene);
  RenderResult render(const gpu::FrameParams &requested, const ProgressFn &progress,
                      LayerSelection layers, const AdaptiveSampling *adaptive,
                      const InfluenceRegion *region, const VideoJob *video = nullptr);
  // Records commands into a command buffer.
  using Recorder = FunctionRef<void(VkCommandBuffer)>;
  // Adds samples [0, end) of `frame` to the accumulators in batches sized by
  // `sizer`, one submission each, each batch recorded by `trace` once
  // frame.sampling holds its samples; `prologue` records commands into the
  // first submission, before its batch, and `epilogue` into the last, after
  // it (both submitted also when `end` is 0). `report` gets the samples done.
  // Returns the number of submissions.
  int trace_batches(gpu::FrameParams &frame, std::uint32_t end, BatchSizer &sizer, Recorder trace,
                    Recorder prologue, Recorder epilogue, FunctionRef<void(std::uint32_t)> report);
  void prepare_video(const gpu::FrameParams &frame, std::optional<base::PixelFormat> plate,
                     std::span<const base::PixelFormat> outputs, bool adaptive);
  // Records the accumulators' clear, ordered before the kernels.
  void record_clear(VkCommandBuffer command_buffer) const;
  // Records adaptive_weights, _solve and _shares (adaptive.glsl) and
  // adaptive_queue_bins and _fill (sample_queue.glsl) after the pilot, over
  // the frame's region: sample_counts (0 outside the region), the adaptive
  // solution and the second pass's queue, ordered before the kernels and
  // the indirect dispatches.
  void record_allocation(VkCommandBuffer command_buffer);
  // Records a second-pass batch of `frame` (adaptive, tracing.y = the pilot):
  // the trace kernel over the queue's pixels that have samples in it.
  void record_queue_batch(VkCommandBuffer command_buffer, const gpu::FrameParams &frame);
  // A kernel's code and its first two specialization constants
  // (KERNEL_FEATURES and the kernel's own); the third, GROUP_LIST, is
  // chosen where it is dispatched.
  struct Kernel {
    std::span<const std::uint32_t> spirv;
    const char *name = nullptr;
    std::uint32_t features = KERNEL_ALL;
    std::uint32_t variant = 0;
  };
  // The trace kernel for the loaded scene and `frame`, over the pixels of
  // the image or of the queue (trace.comp, FROM_QUEUE).
  Kernel trace_kernel(const gpu::FrameParams &frame, bool from_queue = false) const;
  // The resolve kernel writing `layers` (RESOLVE_*).
  static Kernel resolve_kernel(std::uint32_t layers);
  // video_decode.comp or video_encode.comp for frames of `format`.
  static Kernel video_kernel(std::span<const std::uint32_t> spirv, const char *name,
                             base::PixelFormat format);
  // `kernel` over the frame's grid or, with `group_list`, over a group list
  // (buffers.glsl, GROUP_LIST), to be dispatched with a base; built on first
  // use, which for live frames is prepare_video() (a lookup allocates
  // nothing).
  VkPipeline pipeline(const Kernel &kernel, bool group_list = false);
  // Binds `pipeline` and the descriptor set every kernel shares.
  void bind(VkCommandBuffer command_buffer, VkPipeline pipeline) const;
  // Dispatches `pipeline` over the image's tiles, or over `groups`.
  void dispatch(VkCommandBuffer command_buffer, VkPipeline pipeline,
                std::optional<glm::uvec2> groups = std::nullopt) const;
  // Dispatches a tile kernel over the tiles of the frame's region: the
  // frame's grid where the region is the whole frame, else the tile list.
  void dispatch_region(VkCommandBuffer command_buffer, const Kernel &kernel);
  // Dispatches a video kernel for video frame `frame` (gl_WorkGroupID.z:
  // the output; 0 for the camera frame) over the whole frame, or over the
  // video groups of the frame's region.
  void dispatch_video(VkCommandBuffer command_buffer, const Kernel &kernel, std::uint32_t frame,
                      bool region_only);
  // Dispatches `count` groups of a group list, `base_z` as gl_WorkGroupID.z.
  void dispatch_list(VkCommandBuffer command_buffer, std::uint32_t count,
                     std::uint32_t base_z = 0) const;
  // Writes the frame region's tile list and, with `video_groups`, the video
  // kernels' list into the group-list buffer.
  void write_group_lists(bool video_groups);

  // Declaration order is destruction order in reverse: everything made from
  // the device goes before it, and the device before the instance.
  vk::Instance instance;
  vk::Device device;
  vk::DescriptorSet descriptors;
  vk::UniquePipelineLayout pipeline_layout;
  // Every kernel but the two below, by its code and its constants: trace.comp
  // by KERNEL_FEATURES (layout.h) and FROM_QUEUE, resolve.comp by
  // RESOLVE_LAYERS, the video kernels by VIDEO_FORMAT, and each by
  // GROUP_LIST.
  using Constants = std::array<std::uint32_t, 3>;
  std::map<std::pair<const std::uint32_t *, Constants>, vk::UniquePipeline> specialized_pipelines;
  vk::UniquePipeline adaptive_solve;
  vk::UniquePipeline adaptive_queue_bins;
  vk::CommandRunner commands;
  vk::Buffer frame_uniform;
  vk::Buffer video_uniform;
  // 0: the frame's first command, 1: its last; 2, 3: around the adaptive
  // allocation (adaptive frames only).
  vk::TimestampQueries timestamps;
  std::array<vk::Buffer, BINDING_COUNT> buffers; // by binding; BINDING_FRAME unused
  // The kOutputs one after another, then the display image, the sample
  // counts, the adaptive solution and the encoded video outputs.
  vk::Buffer readback;

  bool loaded = false;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  bool has_plate = false;
  gpu::uvec4 counts{};                       // primitives, nodes, lights
  glm::vec3 origin{0.0f};                    // CompiledScene::origin of the loaded scene
  std::uint32_t scene_features = KERNEL_ALL; // scene_kernel_features of the loaded scene
  bool specialize = true;                    // set_kernel_specialization
  // Batch sizes, one per kind of pass, for the loaded scene.
  BatchSizer uniform_sizer;
  BatchSizer second_pass_sizer;
  // The current frame's tiles to trace (influence_region.h).
  InfluenceRegion frame_region;
  // The lengths of the current frame's group lists (written by
  // write_group_lists), and its scratch, kept for its capacity: a live frame
  // allocates nothing.
  std::uint32_t tile_list_count = 0;
  std::uint32_t video_list_count = 0;
  std::vector<std::uint32_t> group_places;
  std::vector<glm::uvec2> video_spans;
};

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

GpuTracer::Impl::Kernel GpuTracer::Impl::video_kernel(std::span<const std::uint32_t> spirv,
                                                      const char *name, base::PixelFormat format) {
  return {spirv, name, KERNEL_ALL, video_format_code(format)};
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

RenderResult GpuTracer::Impl::render(const gpu::FrameParams &requested, const ProgressFn &progress,
                                     LayerSelection selection, const AdaptiveSampling *adaptive,
                                     const InfluenceRegion *wanted_region, const VideoJob *video) {
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
  if (wanted_region != nullptr &&
      (wanted_region->width != width || wanted_region->height != height))
    throw GpuError("influence region is " + std::to_string(wanted_region->width) + "x" +
                   std::to_string(wanted_region->height) + " but the loaded scene is " +
                   std::to_string(width) + "x" + std::to_string(height));
  if (wanted_region != nullptr) {
    frame_region = *wanted_region; // into the storage load() made
  } else {
    frame_region.width = width;
    frame_region.height = height;
    frame_region.rects.assign(1, PixelRect{0, 0, width, height});
  }

  // A live frame: the camera frame into the plate on the device, and the
  // composite into each output's format (video_decode.comp, video_encode.comp).
  const bool decode_plate = video != nullptr && !video->plate.bytes.empty();
  const std::size_t video_outputs = video != nullptr ? video->outputs.size() : 0;
  const VkDeviceSize video_slot_bytes = max_video_bytes(std::size_t(width) * height);
  if (video != nullptr) {
    if (video_outputs > VIDEO_MAX_OUTPUTS)
      throw GpuError("a frame for " + std::to_string(video_outputs) + " outputs; at most " +
                     std::to_string(VIDEO_MAX_OUTPUTS));
    gpu::VideoFrames params{};
    if (decode_plate) {
      params.frames[0] = video_params(video->plate.format, 0);
      copy_rows(video->plate.bytes.data(), base::row_bytes(video->plate.format),
                static_cast<std::uint8_t *>(buffers[BINDING_VIDEO_IN].mapped()),
                base::packed_stride(video->plate.format.pixel, int(width)), video->plate.format);
    }
    for (std::size_t k = 0; k < video_outputs; ++k)
      params.frames[1 + k] =
          video_params(video->outputs[k].format, std::uint32_t(k * video_slot_bytes / 4));
    params.count = gpu::uvec4(std::uint32_t(video_outputs), 0u, 0u, 0u);
    std::memcpy(video_uniform.mapped(), &params, sizeof params);
    frame.image.z = decode_plate ? 1u : 0u;
  }
  // Outputs in the camera frame's own format take its bytes outside the
  // region (they are the composite there, bit for bit: frame_renderer_test),
  // so the video kernels and the resolve need only run over the region; the
  // layers, which the region leaves stale outside it, are not read.
  bool region_video = decode_plate && video_outputs > 0 && !frame_region.whole_frame() &&
                      !selection.composite && !selection.mixed && !selection.real &&
                      !selection.mask_and_depth && !selection.display;
  for (std::size_t k = 0; k < video_outputs; ++k)
    region_video = region_video && same_pixels(video->outputs[k].format, video->plate.format);
  if (!frame_region.whole_frame())
    write_group_lists(region_video);

  // The first batch writes every pixel it traces (trace.comp). Over a
  // smaller region, two kernels read others, which must be zeros: a resolve
  // of the whole frame, and the adaptive weights (a pixel's 3x3
  // neighbourhood reaches past the region's edge).
  const bool reads_untraced_pixels =
      !frame_region.whole_frame() && (!region_video || adaptive != nullptr);

  // Where the read-back buffer holds what comes back.
  const VkDeviceSize layer_bytes = buffers[BINDING_OUT_AUX].size();
  const VkDeviceSize display_offset = kOutputs.size() * layer_bytes;
  const VkDeviceSize display_bytes = buffers[BINDING_OUT_DISPLAY].size();
  const VkDeviceSize counts_offset = display_offset + display_bytes;
  const VkDeviceSize counts_bytes = buffers[BINDING_SAMPLE_COUNTS].size();
  const VkDeviceSize solution_offset = counts_offset + counts_bytes;
  const VkDeviceSize video_offset = solution_offset + sizeof(gpu::AdaptiveSolution);

  const Kernel decode =
      decode_plate ? video_kernel(video_decode_spv, "video_decode.comp", video->plate.format.pixel)
                   : Kernel{};
  std::array<Kernel, VIDEO_MAX_OUTPUTS> encode{};
  for (std::size_t k = 0; k < video_outputs; ++k)
    encode[k] = video_kernel(video_encode_spv, "video_encode.comp", video->outputs[k].format.pixel);

  // The frame's first commands: the clear, and the first timestamp.
  const auto begin_frame = [&](VkCommandBuffer command_buffer) {
    timestamps.reset(command_buffer);
    timestamps.write(command_buffer, 0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
    if (reads_untraced_pixels)
      record_clear(command_buffer);
    if (decode_plate) {
      dispatch_video(command_buffer, decode, 0, region_video);
      vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_ACCESS_SHADER_READ_BIT);
    }
  };
  // Its last: the resolve kernel (which reads sampling.z and tracing.y alone,
  // so it shares the last batch's uniform and submission), the copies to the
  // read-back buffer and the second timestamp.
  std::uint32_t layers = 0;
  layers |=
      selection.composite || video_outputs > 0 ? RESOLVE_COMPOSITE : 0u; // video_encode reads it
  layers |= selection.mixed ? RESOLVE_MIXED : 0u;
  layers |= selection.real ? RESOLVE_REAL : 0u;
  layers |= selection.mask_and_depth ? RESOLVE_MASK_AND_DEPTH : 0u;
  layers |= selection.display ? RESOLVE_DISPLAY : 0u;
  const Kernel resolve = resolve_kernel(layers);
  const auto end_frame = [&](VkCommandBuffer command_buffer) {
    if (region_video)
      dispatch_region(command_buffer, resolve);
    else
      dispatch(command_buffer, pipeline(resolve));
    if (video_outputs > 0) {
      vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_ACCESS_SHADER_READ_BIT);
      for (std::size_t k = 0; k < video_outputs; ++k)
        dispatch_video(command_buffer, encode[k], std::uint32_t(k), region_video);
    }
    vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_ACCESS_TRANSFER_READ_BIT);
    const auto copy = [&](int binding, VkDeviceSize offset, VkDeviceSize bytes) {
      const VkBufferCopy region{0, offset, bytes};
      vkCmdCopyBuffer(command_buffer, buffers[binding].get(), readback.get(), 1, &region);
    };
    const std::array<bool, kOutputs.size()> wanted = {selection.composite, selection.mixed,
                                                      selection.real, selection.mask_and_depth};
    for (std::size_t i = 0; i < kOutputs.size(); ++i)
      if (wanted[i])
        copy(kOutputs[i], i * layer_bytes, layer_bytes);
    if (selection.display)
      copy(BINDING_OUT_DISPLAY, display_offset, display_bytes);
    if (adaptive != nullptr) {
      if (selection.sample_counts)
        copy(BINDING_SAMPLE_COUNTS, counts_offset, counts_bytes);
      copy(BINDING_ADAPTIVE_SOLUTION, solution_offset, sizeof(gpu::AdaptiveSolution));
    }
    for (std::size_t k = 0; k < video_outputs; ++k) {
      base::VideoFormat packed = video->outputs[k].format;
      packed.stride = 0; // the kernel's rows
      const VkBufferCopy region{k * video_slot_bytes, video_offset + k * video_slot_bytes,
                                base::frame_bytes(packed)};
      vkCmdCopyBuffer(command_buffer, buffers[BINDING_VIDEO_OUT].get(), readback.get(), 1, &region);
    }
    vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    timestamps.write(command_buffer, 1, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  };
  // A uniform frame's or a pilot's batch: every pixel of the region.
  const auto trace_region = [&](VkCommandBuffer command_buffer) {
    dispatch_region(command_buffer, trace_kernel(frame));
  };
  const auto report = [&](double done) {
    if (progress)
      progress(static_cast<int>(done), static_cast<int>(total));
  };

  FrameTimings timings;
  if (adaptive == nullptr) {
    frame.tracing.y = 0u;
    timings.submissions = trace_batches(frame, total, uniform_sizer, trace_region, begin_frame,
                                        end_frame, [&](std::uint32_t done) { report(done); });
  } else {
    // adaptive.h: a pilot, each pixel's share from what it saw, the shares.
    const std::uint32_t pilot = adaptive_pilot(*adaptive, total);
    frame.tracing.y = 0u;
    frame.sampling.z = pilot;
    timings.submissions = trace_batches(frame, pilot, uniform_sizer, trace_region, begin_frame, {},
                                        [&](std::uint32_t done) { report(done); });
    frame.tracing.y = pilot;
    frame.sampling.z = total;
    frame.adaptive = adaptive_parameters(*adaptive, pilot, total);
    if (wanted_region != nullptr)
      frame.adaptive.z = float(frame_region.pixels());
    // Only the cap is known here, not the largest share (that would take a
    // read-back); a batch past the largest share dispatches no workgroup.
    const std::uint32_t cap = std::uint32_t(frame.adaptive.y);
    timings.submissions += trace_batches(
        frame, cap - pilot, second_pass_sizer,
        [&](VkCommandBuffer command_buffer) { record_queue_batch(command_buffer, frame); },
        [&](VkCommandBuffer command_buffer) { record_allocation(command_buffer); }, end_frame,
        [&](std::uint32_t done) {
          report(pilot + double(done) * (total - pilot) / (cap - pilot));
        });
  }
  timings.submit_s = seconds_since(start);
  timings.device_s = timestamps.seconds(0, 1).value_or(0.0);
  if (adaptive != nullptr)
    timings.allocation_s = timestamps.seconds(2, 3).value_or(0.0);
  const Clock::time_point unpacking = Clock::now();

  const auto *mapped = static_cast<const std::uint8_t *>(readback.mapped());
  const auto layer = [&](std::size_t slot) {
    return reinterpret_cast<const float *>(mapped + slot * layer_bytes);
  };
  const int w = static_cast<int>(width);
  const int h = static_cast<int>(height);
  RenderResult result;
  if (selection.composite)
    result.composite = vk::unpack_layer(layer(0), w, h, 3, 0);
  if (selection.mixed)
    result.mixed = vk::unpack_layer(layer(1), w, h, 3, 0);
  if (selection.real)
    result.real = vk::unpack_layer(layer(2), w, h, 3, 0);
  if (selection.mask_and_depth) {
    const float *aux = layer(3);
    result.mask = vk::unpack_layer(aux, w, h, 1, 0);  // out_aux.x
    result.depth = vk::unpack_layer(aux, w, h, 1, 1); // out_aux.y
  }
  if (selection.display)
    result.display.assign(mapped + display_offset, mapped + display_offset + display_bytes);
  result.camera_rays = frame_region.pixels() * total;
  if (adaptive != nullptr) {
    gpu::AdaptiveSolution solution;
    std::memcpy(&solution, mapped + solution_offset, sizeof solution);
    result.camera_rays = std::uint64_t(solution.rays.y) << 32 | solution.rays.x;
    if (selection.sample_counts) {
      const auto *shares = reinterpret_cast<const std::uint32_t *>(mapped + counts_offset);
      result.sample_counts.assign(shares, shares + std::size_t(width) * height);
    }
  }
  for (std::size_t k = 0; k < video_outputs; ++k) {
    const VideoBuffer &out = video->outputs[k];
    const std::uint8_t *encoded = mapped + video_offset + k * video_slot_bytes;
    const std::size_t encoded_stride = base::packed_stride(out.format.pixel, out.format.width);
    if (region_video) {
      copy_rows(video->plate.bytes.data(), base::row_bytes(video->plate.format), out.bytes.data(),
                base::row_bytes(out.format), out.format);
      copy_rects(encoded, encoded_stride, out.bytes.data(), base::row_bytes(out.format), out.format,
                 frame_region.rects);
    } else {
      copy_rows(encoded, encoded_stride, out.bytes.data(), base::row_bytes(out.format), out.format);
    }
  }
  timings.unpack_s = seconds_since(unpacking);
  result.timings = timings;
  result.seconds = seconds_since(start);
  return result;
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

int GpuTracer::Impl::trace_batches(gpu::FrameParams &frame, std::uint32_t end, BatchSizer &sizer,
                                   Recorder trace, Recorder prologue, Recorder epilogue,
                                   FunctionRef<void(std::uint32_t)> report) {
  // One uniform buffer suffices because each batch is waited for before the
  // next one rewrites it.
  int submissions = 0;
  std::uint32_t done = 0;
  do {
    const std::uint32_t batch = std::min(sizer.next(), end - done);
    frame.sampling.x = done;
    frame.sampling.y = done + batch;
    std::memcpy(frame_uniform.mapped(), &frame, sizeof frame);

    VkCommandBuffer command_buffer = commands.begin();
    if (done == 0 && prologue)
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
    const Clock::time_point submitted = Clock::now();
    commands.submit_and_wait();
    ++submissions;
    // A batch that carries the frame's set-up or resolve looks a little
    // dearer per sample than it is: the next batch comes out a little smaller.
    if (batch > 0)
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
  for (const bool group_list : {false, true}) {
    static_cast<void>(pipeline(trace_kernel(frame), group_list));
    static_cast<void>(pipeline(resolve_kernel(RESOLVE_COMPOSITE), group_list));
    if (plate)
      static_cast<void>(
          pipeline(video_kernel(video_decode_spv, "video_decode.comp", *plate), group_list));
    for (const base::PixelFormat out : outputs)
      static_cast<void>(
          pipeline(video_kernel(video_encode_spv, "video_encode.comp", out), group_list));
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
                                     const InfluenceRegion *region) {
  const VideoJob job{plate, outputs};
  return impl_->render(frame, {}, LayerSelection{false, false, false, false, false, false},
                       adaptive, region, &job);
}

RenderResult GpuTracer::render_adaptive(const gpu::FrameParams &frame,
                                        const AdaptiveSampling &settings,
                                        const ProgressFn &progress, LayerSelection layers,
                                        const InfluenceRegion *region) {
  return impl_->render(frame, progress, layers, &settings, region);
}

} // namespace camhead::renderer
