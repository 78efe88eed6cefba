// A frame on the GPU tracer (gpu_tracer_impl.h), still or live, in four
// steps: its plan (what it asks for, checked against the loaded scene; a
// live frame's camera frame written into the device's memory), its batches
// (a first submission that starts the frame, a last that ends it), and what
// comes back: the layers of a still, the encoded outputs of a live frame.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>

#include "camhead/renderer/adaptive.h"
#include "frame_checks.h"
#include "gpu_tracer_impl.h"
#include "gpu_video_frames.h"

namespace camhead::renderer {

struct GpuTracer::Impl::Frame {
  gpu::FrameParams params; // as the kernels see it
  // Samples [first, total) of the pattern this frame traces; the composite is
  // the mean of [0, total) (a live frame that continues a history: first > 0).
  std::uint32_t first = 0;
  std::uint32_t total = 0;
  LayerSelection selection;
  const AdaptiveSampling *adaptive = nullptr;
  bool region_given = false; // else the whole frame, and no region in the adaptive solve
  // A live frame: the camera frame into the plate on the device, and the
  // composite into each output's format (video_decode.comp, video_encode.comp).
  const VideoJob *video = nullptr;
  bool decode_plate = false;
  std::size_t video_outputs = 0;
  // The video kernels and the resolve over the region alone (plan_frame).
  bool region_video = false;
  // Kernels read pixels outside the region, which must be zeros.
  bool reads_untraced_pixels = false;
  // A live frame reconstructed (frame.reconstruct, reconstruct.glsl): its
  // first passes (`filter_rows`, else those of the frame before stand),
  // after `clear_filter` the clear of their per-pixel state.
  bool reconstruct = false;
  bool filter_rows = false;
  bool clear_filter = false;
  Kernel decode;
  std::array<Kernel, VIDEO_MAX_OUTPUTS> encode{};
  Kernel resolve;
};

RenderResult GpuTracer::Impl::render(const gpu::FrameParams &requested, const ProgressFn &progress,
                                     LayerSelection selection, const AdaptiveSampling *adaptive,
                                     const InfluenceRegion *region, const VideoJob *video) {
  const GpuClock::time_point start = GpuClock::now();
  Frame frame = plan_frame(requested, selection, adaptive, region, video);
  FrameTimings timings = trace_frame(frame, progress);
  // Only a frame that ran leaves its reconstruction's state to the next.
  filter_ready = frame.reconstruct;
  filter_settings = frame.params.reconstruct;
  timings.submit_s = seconds_since(start);
  const GpuClock::time_point unpacking = GpuClock::now();
  RenderResult result = read_layers(frame);
  read_outputs(frame);
  timings.unpack_s = seconds_since(unpacking);
  result.timings = timings;
  result.seconds = seconds_since(start);
  return result;
}

GpuTracer::Impl::Frame GpuTracer::Impl::plan_frame(const gpu::FrameParams &requested,
                                                   LayerSelection selection,
                                                   const AdaptiveSampling *adaptive,
                                                   const InfluenceRegion *region,
                                                   const VideoJob *video) {
  if (!loaded)
    throw GpuError("GpuTracer::render() before a successful load()");
  if (requested.image.x != width || requested.image.y != height)
    throw GpuError("frame is " + std::to_string(requested.image.x) + "x" +
                   std::to_string(requested.image.y) + " but the loaded scene is " +
                   std::to_string(width) + "x" + std::to_string(height));
  if (requested.sampling.z == 0)
    throw GpuError("frame asks for 0 samples per pixel (sampling.z)");
  if (region != nullptr && (region->width != width || region->height != height))
    throw GpuError("influence region is " + std::to_string(region->width) + "x" +
                   std::to_string(region->height) + " but the loaded scene is " +
                   std::to_string(width) + "x" + std::to_string(height));
  const std::size_t video_outputs = video != nullptr ? video->outputs.size() : 0;
  if (video_outputs > VIDEO_MAX_OUTPUTS)
    throw GpuError("a frame for " + std::to_string(video_outputs) + " outputs; at most " +
                   std::to_string(VIDEO_MAX_OUTPUTS));

  Frame frame;
  frame.total = requested.sampling.z;
  if (video != nullptr) {
    const GpuTracer::SampleRange range = video->samples;
    // first == end: a history already whole, resolved again over a new plate.
    if (!(range.first <= range.end && range.end > 0 && range.end <= requested.sampling.z))
      throw GpuError("samples [" + std::to_string(range.first) + ", " + std::to_string(range.end) +
                     ") of a pattern of " + std::to_string(requested.sampling.z));
    if (range.first > 0 && adaptive != nullptr)
      throw GpuError("an adaptive frame does not continue the frames before");
    frame.first = range.first;
    frame.total = range.end;
  }
  frame.selection = selection;
  frame.adaptive = adaptive;
  frame.region_given = region != nullptr;
  frame.video = video;
  frame.video_outputs = video_outputs;
  frame.decode_plate = video != nullptr && !video->plate.bytes.empty();
  // The kernels index the buffers with these, so they come from what load()
  // uploaded: a stale or hand-made FrameParams must not read out of bounds.
  frame.params = requested;
  frame.params.cam_position -= gpu::vec4(origin, 0.0f); // into the compiled scene's frame
  frame.params.image.z = requested.image.z != 0 && has_plate ? 1u : 0u;
  frame.params.image.w = counts.z;
  if (region != nullptr) {
    frame_region = *region; // into the storage load() made
  } else {
    frame_region.width = width;
    frame_region.height = height;
    frame_region.rects.assign(1, PixelRect{0, 0, width, height});
  }

  if (video != nullptr) {
    gpu::VideoFrames params{};
    if (frame.decode_plate) {
      params.frames[0] = video_params(video->plate.format, 0);
      copy_rows(video->plate.bytes.data(), base::row_bytes(video->plate.format),
                static_cast<std::uint8_t *>(buffers[BINDING_VIDEO_IN].mapped()),
                base::packed_stride(video->plate.format.pixel, int(width)), video->plate.format);
      frame.decode = decode_kernel(video->plate.format.pixel);
    }
    for (std::size_t k = 0; k < video_outputs; ++k) {
      params.frames[1 + k] = video_params(video->outputs[k].format,
                                          std::uint32_t(k * readback_layout.video_slot_bytes / 4));
      frame.encode[k] = encode_kernel(video->outputs[k].format.pixel);
    }
    params.count = gpu::uvec4(std::uint32_t(video_outputs), 0u, 0u, 0u);
    std::memcpy(video_uniform.mapped(), &params, sizeof params);
    frame.params.image.z = frame.decode_plate ? 1u : 0u;
  }
  // Outputs in the camera frame's own format take its bytes outside the
  // region (they are the composite there, bit for bit: frame_renderer_test),
  // so the video kernels and the resolve need only run over the region; the
  // layers, which the region leaves stale outside it, are not read.
  frame.region_video = frame.decode_plate && video_outputs > 0 && !frame_region.whole_frame() &&
                       !selection.composite && !selection.mixed && !selection.real &&
                       !selection.mask_and_depth && !selection.display;
  for (std::size_t k = 0; k < video_outputs; ++k)
    frame.region_video =
        frame.region_video && same_pixels(video->outputs[k].format, video->plate.format);
  if (!frame_region.whole_frame())
    write_group_lists(frame.region_video);
  // The first batch writes every pixel it traces (trace.comp). Over a
  // smaller region, two kernels read others, which must be zeros: a resolve
  // of the whole frame, and the adaptive weights (a pixel's 3x3
  // neighbourhood reaches past the region's edge).
  frame.reads_untraced_pixels =
      !frame_region.whole_frame() && (!frame.region_video || adaptive != nullptr);

  frame.reconstruct = requested.reconstruct.x > 0.0f;
  if (frame.reconstruct && (video == nullptr || adaptive != nullptr))
    throw GpuError("only a live frame that is not adaptive reconstructs");
  frame.clear_filter = frame.reconstruct && (frame.first == 0 || !filter_ready);
  // A frame that adds no sample to a history (a whole one) reads the rows'
  // sums that the frame before left, if it made them as this one would.
  frame.filter_rows = frame.reconstruct && !(frame.first == frame.total && filter_ready &&
                                             filter_settings == requested.reconstruct);
  filter_ready = false; // until the frame has run: render()

  std::uint32_t layers = 0;
  layers |= frame.reconstruct ? RESOLVE_FILTERED : 0u;
  // video_encode reads it; a live frame always writes it, so that one
  // without outputs takes a resolve that prepare_video() built.
  layers |= selection.composite || video != nullptr ? RESOLVE_COMPOSITE : 0u;
  layers |= selection.mixed ? RESOLVE_MIXED : 0u;
  layers |= selection.real ? RESOLVE_REAL : 0u;
  layers |= selection.mask_and_depth ? RESOLVE_MASK_AND_DEPTH : 0u;
  layers |= selection.display ? RESOLVE_DISPLAY : 0u;
  frame.resolve = resolve_kernel(layers);
  return frame;
}

void GpuTracer::Impl::record_frame_start(VkCommandBuffer command_buffer, const Frame &frame) {
  timestamps.reset(command_buffer);
  timestamps.write(command_buffer, 0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
  if (frame.reads_untraced_pixels && frame.first == 0) // else the history's start cleared them
    record_clear(command_buffer);
  if (frame.decode_plate) {
    dispatch_video(command_buffer, frame.decode, 0, frame.region_video);
    vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_READ_BIT);
  }
}

void GpuTracer::Impl::record_reconstruction(VkCommandBuffer command_buffer, bool clear) {
  if (clear) {
    vkCmdFillBuffer(command_buffer, buffers[BINDING_FILTER_PIXELS].get(), 0, VK_WHOLE_SIZE, 0);
    vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  }
  for (const std::uint32_t pass : {0u, 1u}) {
    dispatch_region(command_buffer, reconstruct_kernel(pass));
    vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  }
}

// The resolve and the reconstruction read of the frame parameters the
// samples held (sampling.y, the last batch's end), tracing.y and those that
// no batch changes, so they share the last batch's uniform and submission.
void GpuTracer::Impl::record_frame_end(VkCommandBuffer command_buffer, const Frame &frame) {
  if (frame.filter_rows)
    record_reconstruction(command_buffer, frame.clear_filter);
  if (frame.region_video)
    dispatch_region(command_buffer, frame.resolve);
  else
    dispatch(command_buffer, pipeline(frame.resolve));
  if (frame.video_outputs > 0) {
    vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_READ_BIT);
    for (std::size_t k = 0; k < frame.video_outputs; ++k)
      dispatch_video(command_buffer, frame.encode[k], std::uint32_t(k), frame.region_video);
  }
  vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                     VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_TRANSFER_READ_BIT);
  const ReadbackLayout &r = readback_layout;
  const auto copy = [&](int binding, VkDeviceSize offset, VkDeviceSize bytes) {
    const VkBufferCopy region{0, offset, bytes};
    vkCmdCopyBuffer(command_buffer, buffers[binding].get(), readback.get(), 1, &region);
  };
  const LayerSelection &selection = frame.selection;
  const std::array<bool, kOutputs.size()> wanted = {selection.composite, selection.mixed,
                                                    selection.real, selection.mask_and_depth};
  for (std::size_t i = 0; i < kOutputs.size(); ++i)
    if (wanted[i])
      copy(kOutputs[i], i * r.layer_bytes, r.layer_bytes);
  if (selection.display)
    copy(BINDING_OUT_DISPLAY, r.display_offset, r.display_bytes);
  if (frame.adaptive != nullptr) {
    if (selection.sample_counts)
      copy(BINDING_SAMPLE_COUNTS, r.counts_offset, r.counts_bytes);
    copy(BINDING_ADAPTIVE_SOLUTION, r.solution_offset, sizeof(gpu::AdaptiveSolution));
  }
  for (std::size_t k = 0; k < frame.video_outputs; ++k) {
    base::VideoFormat packed = frame.video->outputs[k].format;
    packed.stride = 0; // the kernel's rows
    const VkBufferCopy region{k * r.video_slot_bytes, r.video_offset + k * r.video_slot_bytes,
                              base::frame_bytes(packed)};
    vkCmdCopyBuffer(command_buffer, buffers[BINDING_VIDEO_OUT].get(), readback.get(), 1, &region);
  }
  vk::memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  timestamps.write(command_buffer, 1, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
}

FrameTimings GpuTracer::Impl::trace_frame(Frame &frame, const ProgressFn &progress) {
  gpu::FrameParams &params = frame.params;
  const std::uint32_t total = frame.total;
  const auto report = [&](double done) {
    if (progress)
      progress(static_cast<int>(done), static_cast<int>(total));
  };
  // A uniform frame's or a pilot's batch: every pixel of the region.
  const auto trace_region = [&](VkCommandBuffer command_buffer) {
    dispatch_region(command_buffer, trace_kernel(params));
  };
  const auto start = [&](VkCommandBuffer command_buffer) {
    record_frame_start(command_buffer, frame);
  };
  const auto end = [&](VkCommandBuffer command_buffer) { record_frame_end(command_buffer, frame); };

  FrameTimings timings;
  if (frame.adaptive == nullptr) {
    params.tracing.y = 0u;
    timings.submissions = trace_batches(params, frame.first, total, uniform_sizer, trace_region,
                                        start, end, [&](std::uint32_t done) { report(done); });
  } else {
    // adaptive.h: a pilot, each pixel's share from what it saw, the shares.
    const std::uint32_t pilot = adaptive_pilot(*frame.adaptive, total);
    params.tracing.y = 0u;
    params.sampling.z = pilot;
    timings.submissions = trace_batches(params, 0, pilot, uniform_sizer, trace_region, start, {},
                                        [&](std::uint32_t done) { report(done); });
    params.tracing.y = pilot;
    params.sampling.z = total;
    params.adaptive = adaptive_parameters(*frame.adaptive, pilot, total);
    if (frame.region_given)
      params.adaptive.z = float(frame_region.pixels());
    // Only the cap is known here, not the largest share (that would take a
    // read-back); a batch past the largest share dispatches no workgroup.
    const std::uint32_t cap = std::uint32_t(params.adaptive.y);
    timings.submissions += trace_batches(
        params, 0, cap - pilot, second_pass_sizer,
        [&](VkCommandBuffer command_buffer) { record_queue_batch(command_buffer, params); },
        [&](VkCommandBuffer command_buffer) { record_allocation(command_buffer); }, end,
        [&](std::uint32_t done) {
          report(pilot + double(done) * (total - pilot) / (cap - pilot));
        });
  }
  timings.device_s = timestamps.seconds(0, 1).value_or(0.0);
  if (frame.adaptive != nullptr)
    timings.allocation_s = timestamps.seconds(2, 3).value_or(0.0);
  return timings;
}

RenderResult GpuTracer::Impl::read_layers(const Frame &frame) const {
  const ReadbackLayout &r = readback_layout;
  const auto *mapped = static_cast<const std::uint8_t *>(readback.mapped());
  const auto layer = [&](std::size_t slot) {
    return reinterpret_cast<const float *>(mapped + slot * r.layer_bytes);
  };
  const int w = static_cast<int>(width);
  const int h = static_cast<int>(height);
  const LayerSelection &selection = frame.selection;
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
    result.display.assign(mapped + r.display_offset, mapped + r.display_offset + r.display_bytes);
  result.camera_rays = frame_region.pixels() * (frame.total - frame.first);
  if (frame.adaptive != nullptr) {
    gpu::AdaptiveSolution solution;
    std::memcpy(&solution, mapped + r.solution_offset, sizeof solution);
    result.camera_rays = std::uint64_t(solution.rays.y) << 32 | solution.rays.x;
    if (selection.sample_counts) {
      const auto *shares = reinterpret_cast<const std::uint32_t *>(mapped + r.counts_offset);
      result.sample_counts.assign(shares, shares + std::size_t(width) * height);
    }
  }
  return result;
}

void GpuTracer::Impl::read_outputs(const Frame &frame) const {
  const ReadbackLayout &r = readback_layout;
  const auto *mapped = static_cast<const std::uint8_t *>(readback.mapped());
  for (std::size_t k = 0; k < frame.video_outputs; ++k) {
    const VideoBuffer &out = frame.video->outputs[k];
    const VideoFrame &plate = frame.video->plate;
    const std::uint8_t *encoded = mapped + r.video_offset + k * r.video_slot_bytes;
    const std::size_t encoded_stride = base::packed_stride(out.format.pixel, out.format.width);
    if (frame.region_video) {
      copy_rows(plate.bytes.data(), base::row_bytes(plate.format), out.bytes.data(),
                base::row_bytes(out.format), out.format);
      copy_rects(encoded, encoded_stride, out.bytes.data(), base::row_bytes(out.format), out.format,
                 frame_region.rects);
    } else {
      copy_rows(encoded, encoded_stride, out.bytes.data(), base::row_bytes(out.format), out.format);
    }
  }
}

} // namespace camhead::renderer
