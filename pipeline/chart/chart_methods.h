// The methods of `camhead bench chart` (chart_command.cpp): how each makes
// a frame of a scene at a budget of rays per pixel, timed on the GPU, and
// the table the chart, its CSV and its legend follow. A new sampler is one
// more entry in methods() with its own run function.
#pragma once

#include <limits>
#include <span>
#include <vector>

#include <glm/vec4.hpp>

#include "camhead/renderer/dof_gather.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/image.h"
#include "camhead/renderer/scene.h"
#include "chart/chart_plot.h"

namespace camhead::cli::chart {

// Frames timed for each setting, after untimed ones.
struct Timing {
  int frames = 5;
  int warmup = 2;
};

// What a method needs to make frames of one scene.
struct Context {
  const renderer::Scene &scene;
  renderer::GpuTracer &tracer;
  renderer::DofGather &gather;
  Timing timing;
  std::span<const glm::vec4> plate; // I_c for the gather's composite; empty without
  float max_blur_radius_px = 0.0f;  // of the scene's depth range, for the gather
};

struct Measurement {
  renderer::Image composite;
  double frame_s = 0.0;
  double post_s = std::numeric_limits<double>::quiet_NaN(); // image-space pass, part of frame_s
};

struct Method {
  const char *name;         // CSV and legend
  const char *description;  // --help
  std::vector<int> budgets; // rays per pixel
  Rgb color;
  Marker marker;
  Measurement (*run)(Context &, int rpp);
};

[[nodiscard]] const std::vector<Method> &methods();

} // namespace camhead::cli::chart
