// See chart_methods.h.
#include "chart/chart_methods.h"

#include <algorithm>
#include <functional>
#include <vector>

#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/frame_settings.h"

namespace camhead::cli::chart {

using namespace camhead::renderer;

namespace {

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Median of `frames` timed calls after `warmup` untimed ones; `frame` returns
// the seconds of one call.
double median_seconds(const Timing &timing, const std::function<double()> &frame) {
  std::vector<double> times;
  for (int i = 0; i < timing.warmup + timing.frames; ++i) {
    const double s = frame();
    if (i >= timing.warmup)
      times.push_back(s);
  }
  return median(times);
}

// A frame's time as the chart counts it: the device's own timestamps where
// it has them (a host clock adds the latency of submitting and waiting,
// which is most of a frame under 3 ms on an H100 and the same for every
// method), else the wall time of the call.
double frame_seconds(const RenderResult &r) {
  return r.timings.device_s > 0.0 ? r.timings.device_s : r.seconds;
}

// The tracer's frame at `rpp` with camera sampler `sampler`.
Measurement run_traced(Context &c, int rpp, CameraSampler sampler) {
  gpu::FrameParams frame = make_frame_params(c.scene, rpp);
  set_camera_sampler(frame, sampler);
  Measurement m;
  m.frame_s = median_seconds(c.timing, [&] {
    return frame_seconds(c.tracer.render(frame, {}, LayerSelection::display_only()));
  });
  m.composite = c.tracer.render(frame).composite;
  return m;
}

// 1. The tracer as it is: stratified jittered pixel and lens samples
//    (method.md section 2).
Measurement run_uniform(Context &c, int rpp) {
  return run_traced(c, rpp, CameraSampler::cmj);
}

// 1b. The same budgets with the low-discrepancy sampler: pixel and aperture
//     jointly from Owen-scrambled Sobol' (sampling.glsl).
Measurement run_sobol(Context &c, int rpp) {
  return run_traced(c, rpp, CameraSampler::sobol);
}

// 2. Image-space depth of field: a pinhole render (aperture radius 0) at
//    `rpp` for antialiasing, blurred by dof_gather.comp. Frame time = the
//    pinhole frame (up to the display image in host memory) + the gather
//    kernel with its input on the device, which is what a frame that ran
//    both on one GPU would take; the host round trip the gather gets its
//    input through here is not counted.
Measurement run_pinhole_gather(Context &c, int rpp) {
  gpu::FrameParams pinhole = make_frame_params(c.scene, rpp);
  set_pinhole(pinhole);
  const gpu::FrameParams lens = make_frame_params(c.scene, rpp);
  const double trace_s = median_seconds(c.timing, [&] {
    return frame_seconds(c.tracer.render(pinhole, {}, LayerSelection::display_only()));
  });
  const RenderResult layers = c.tracer.render(pinhole);
  DofGatherSettings settings;
  settings.max_radius_px = c.max_blur_radius_px;
  Measurement m;
  const double gather_s = median_seconds(c.timing, [&] {
    DofGatherResult r = c.gather.apply(layers, lens, c.plate, settings);
    m.composite = std::move(r.image.composite);
    return r.device_s > 0.0 ? r.device_s : r.gather_s;
  });
  m.frame_s = trace_s + gather_s;
  m.post_s = gather_s;
  return m;
}

// 3. Adaptive ray budget (renderer adaptive.h): `rpp` rays per pixel on
//    average, a pilot then each pixel's share by its variance and blur, no
//    share over `max_factor` times the mean.
Measurement run_adaptive_capped(Context &c, int rpp, float max_factor) {
  const gpu::FrameParams frame = make_frame_params(c.scene, rpp);
  AdaptiveSampling settings;
  settings.max_factor = max_factor;
  Measurement m;
  m.frame_s = median_seconds(c.timing, [&] {
    return frame_seconds(
        c.tracer.render_adaptive(frame, settings, {}, LayerSelection::display_only()));
  });
  m.composite = c.tracer.render_adaptive(frame, settings).composite;
  return m;
}

Measurement run_adaptive(Context &c, int rpp) {
  return run_adaptive_capped(c, rpp, AdaptiveSampling{}.max_factor);
}

// 3b. The same with no share over 4x the mean: on a GPU the second pass
//     lasts as long as its longest invocation, one pixel's whole share
//     (bench/RESULTS.md, "Adaptive on a GPU: the longest share").
Measurement run_adaptive_cap4(Context &c, int rpp) {
  return run_adaptive_capped(c, rpp, 4.0f);
}

} // namespace

// The method table: a new sampler (low-discrepancy, adaptive) is one more
// entry here with its own run function; the chart, CSV and legend follow.
const std::vector<Method> &methods() {
  static const std::vector<Method> table = {
      {"uniform",
       "thin-lens tracer, stratified jittered sampling (method.md 2)",
       {1, 4, 9, 16, 25, 49, 100},
       {31, 119, 180},
       Marker::circle,
       run_uniform},
      {"sobol",
       "thin-lens tracer, Owen-scrambled Sobol' pixel and lens samples (sampling.glsl)",
       {1, 4, 9, 16, 25, 49, 100},
       {255, 127, 14},
       Marker::triangle,
       run_sobol},
      {"pinhole+gather",
       "pinhole render + depth-aware gather blur (dof_gather.comp)",
       {1, 4, 16},
       {214, 39, 40},
       Marker::square,
       run_pinhole_gather},
      {"adaptive",
       "thin-lens tracer, adaptive ray budget per pixel from a pilot (renderer adaptive.h)",
       {4, 9, 16, 25, 49},
       {44, 160, 44},
       Marker::diamond,
       run_adaptive},
      {"adaptive-cap4",
       "adaptive, no pixel over 4x the mean rays (a GPU's longest thread 4x shorter)",
       {4, 9, 16, 25, 49},
       {148, 103, 189},
       Marker::diamond,
       run_adaptive_cap4},
  };
  return table;
}

} // namespace camhead::cli::chart
