// The GPU tracer's state and steps (gpu_tracer.h), shared by the files
// that implement them: gpu_tracer.cpp (the device, the scene's upload, the
// pipelines and their dispatch, the batches), gpu_frame.cpp (a frame, still
// or live, from its plan to what comes back).
//
// Thread safety: a GpuTracer is used by one thread at a time.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/gpu_tracer.h"
#include "function_ref.h"
#include "vulkan_context.h"

namespace camhead::renderer {

using GpuClock = std::chrono::steady_clock;

inline double seconds_since(GpuClock::time_point start) {
  return std::chrono::duration<double>(GpuClock::now() - start).count();
}

// Samples per pixel of the next trace submission, from the measured cost of
// the previous one. Submissions of about kTargetSeconds stay well clear of
// display-driver watchdogs (about 2 s) and report progress often, while the
// per-submission overhead stays negligible. A sizer lives as long as the
// loaded scene, so that a live frame of a few samples, once one frame has
// been measured, is one submission (on lavapipe, of at most 16 samples a
// pixel: DriverQuirks::max_samples_per_dispatch).
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

// The per-pixel buffers, in the order the read-back buffer holds the outputs.
inline constexpr std::array<int, 4> kOutputs = {BINDING_OUT_COMPOSITE, BINDING_OUT_MIXED,
                                                BINDING_OUT_REAL, BINDING_OUT_AUX};
inline constexpr std::array<int, 3> kAccumulators = {BINDING_ACCUM_MIXED, BINDING_ACCUM_REAL,
                                                     BINDING_ACCUM_AUX};

struct GpuTracer::Impl {
  explicit Impl(const std::string &wanted);
  ~Impl() { device.wait_idle(); }

  void load(const CompiledScene &scene);

  // A frame, still or live (gpu_frame.cpp), in its steps.
  struct Frame;
  RenderResult render(const gpu::FrameParams &requested, const ProgressFn &progress,
                      LayerSelection layers, const AdaptiveSampling *adaptive,
                      const InfluenceRegion *region, const VideoJob *video = nullptr);
  // What the frame asks for, checked against what load() uploaded; the
  // camera frame written into the device's memory and the group lists
  // written (a live frame).
  Frame plan_frame(const gpu::FrameParams &requested, LayerSelection selection,
                   const AdaptiveSampling *adaptive, const InfluenceRegion *region,
                   const VideoJob *video);
  // The frame's first commands (the clear, the camera frame's decode) and its
  // last (the resolve, the outputs' encode, the copies into the read-back).
  void record_frame_start(VkCommandBuffer command_buffer, const Frame &frame);
  void record_frame_end(VkCommandBuffer command_buffer, const Frame &frame);
  // Every batch of the frame, one submission each, waited for.
  FrameTimings trace_frame(Frame &frame, const ProgressFn &progress);
  // What comes back: the layers asked for (a still), the encoded outputs
  // into the caller's buffers (a live frame).
  RenderResult read_layers(const Frame &frame) const;
  void read_outputs(const Frame &frame) const;
  // Records commands into a command buffer.
  using Recorder = FunctionRef<void(VkCommandBuffer)>;
  // Adds samples [first, end) of `frame` to the accumulators in batches
  // sized by `sizer` (and no larger than the device's
  // DriverQuirks::max_samples_per_dispatch), one submission each, each batch recorded by `trace`
  // once frame.sampling holds its samples; `prologue` records commands into
  // the first submission, before its batch, and `epilogue` into the last,
  // after it (both submitted also when there are none). `report` gets the
  // samples done. Returns the number of submissions.
  int trace_batches(gpu::FrameParams &frame, std::uint32_t first, std::uint32_t end,
                    BatchSizer &sizer, Recorder trace, Recorder prologue, Recorder epilogue,
                    FunctionRef<void(std::uint32_t)> report);
  void prepare_video(const gpu::FrameParams &frame, std::optional<base::PixelFormat> plate,
                     std::span<const base::PixelFormat> outputs, bool adaptive);
  // Records the accumulators' clear, ordered before the kernels.
  void record_clear(VkCommandBuffer command_buffer) const;
  // Records the reconstruction's first passes over the frame's region
  // (reconstruct.glsl), after `clear` the clear of its per-pixel state,
  // ordered before the resolve.
  void record_reconstruction(VkCommandBuffer command_buffer, bool clear);
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
  // chosen where it is dispatched. Pipelines are looked up by the code's
  // address, and every translation unit that includes a *_spv.h has a copy
  // of its own: Kernels are made by the functions below (gpu_tracer.cpp),
  // nowhere else.
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
  // reconstruct.comp's pass `pass` (reconstruct.glsl).
  static Kernel reconstruct_kernel(std::uint32_t pass);
  // video_decode.comp and video_encode.comp for frames of `format`.
  static Kernel decode_kernel(base::PixelFormat format);
  static Kernel encode_kernel(base::PixelFormat format);
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
  // counts, the adaptive solution and the encoded video outputs: where each
  // lies, set by load().
  vk::Buffer readback;
  struct ReadbackLayout {
    VkDeviceSize layer_bytes = 0;
    VkDeviceSize display_offset = 0, display_bytes = 0;
    VkDeviceSize counts_offset = 0, counts_bytes = 0;
    VkDeviceSize solution_offset = 0;
    VkDeviceSize video_offset = 0, video_slot_bytes = 0;
  } readback_layout;

  bool loaded = false;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  bool has_plate = false;
  gpu::uvec4 counts{};                       // primitives, nodes, lights
  glm::vec3 origin{0.0f};                    // CompiledScene::origin of the loaded scene
  std::uint32_t scene_features = KERNEL_ALL; // scene_kernel_features of the loaded scene
  bool specialize = true;                    // set_kernel_specialization
  // Whether BINDING_FILTER_PIXELS is zero outside the frame's region, and
  // it and the rows' sums are those of the accumulators with
  // `filter_settings` (FrameParams::reconstruct): set by a reconstructed
  // frame that ran, which clears it where a history starts or the frame
  // before did not reconstruct; any other frame unsets it.
  bool filter_ready = false;
  gpu::vec4 filter_settings{0.0f};
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

} // namespace camhead::renderer
