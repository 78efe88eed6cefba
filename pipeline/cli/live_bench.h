// camhead bench live (live_bench_command.cpp): what the measurement and its
// reports share. The command renders and measures; live_bench_report.cpp
// turns the measurements into the tables, CSV files and pictures.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "camhead/renderer/scene.h"

namespace camhead::cli::live {

struct LiveArgs {
  std::filesystem::path scene;
  std::filesystem::path out_dir = "bench";
  int ref_rpp = 1024;
  double rpp = 1.0; // rays per pixel of a live frame, a mean
  int frames = 50;
  double fps = 25.0;
  int threads = 0;
  double reconstruct = 1.0; // the filter's strength; 0: off
  std::uint32_t seed = 0;   // 0: the figures in bench/RESULTS.md
  std::string executor = "cpu";
  std::string device; // the Vulkan device, for the GPU executor
};

// A lens state of the rig (scenes/lenses/make_sim_focus_pull.py's holds).
struct LensPoint {
  std::string name;
  float focus_m;
  float f_number;
};

// For the chart of error against frame time: a method's error and the
// median of its frame times, its frame rendered several times with the
// same samples (the same error each time).
struct TimedFrame {
  double error = 0.0;
  double seconds = 0.0;
  double rays = 0.0; // a pixel of the region, as traced (a pull frame of
                     // moved samples spends no fraction of a ray)
};

// Renders a frame's time is the median of.
inline constexpr int kTimings = 3;

// The rays per pixel of the chart of error against frame time: fresh frames
// as before, and live frames across the frame budget's range on two cores
// (1 to 2) and above it.
inline constexpr std::array<std::uint32_t, 6> kUniformRays = {1, 2, 4, 9, 16, 49};
inline constexpr std::array<double, 4> kLiveRays = {1.0, 1.5, 2.0, 4.0};

// One lens state's figures: a still shot's error frame after frame, or a
// pull frame's.
struct RestCurve {
  LensPoint lens;
  double region = 0.0;
  double uniform1 = 0.0, uniform9 = 0.0, uniform49 = 0.0;
  std::vector<double> seconds, error;
  std::vector<std::uint32_t> samples;
  // Pull frames: the live frame afresh (no samples moved from the frames
  // before) and its samples held.
  double afresh = 0.0;
  std::uint32_t afresh_samples = 0;
  // Pull frames: 1 rpp, the live frame, 9 rpp, the reference (RGB, 8 bits).
  std::vector<std::vector<std::uint8_t>> pictures;
  // Pull frames: error and frame time of fresh frames (kUniformRays) and of
  // live frames with the frames before moved and afresh (kLiveRays).
  std::vector<TimedFrame> uniform, moved, fresh;
};

// Rays per pixel as a person writes them: 2, 1.5.
[[nodiscard]] std::string rays_text(double rpp);
// `v` through printf's `format`.
[[nodiscard]] std::string fmt(double v, const char *format = "%.4f");

// The tables on standard output: the still shots, the pull frames, and the
// pull frames' error against frame time.
void print_tables(const LiveArgs &args, const std::filesystem::path &scene_file,
                  const renderer::Scene &scene, const std::vector<RestCurve> &rest,
                  const std::vector<RestCurve> &pull);

// DIR/live.csv and live.png (the still shots' error against time),
// live_speed.csv and live_speed.png (the pull frames' error against frame
// time) and live_pull.png (the pull frames, cropped).
void write_reports(const LiveArgs &args, const renderer::Scene &scene,
                   const std::vector<RestCurve> &rest, const std::vector<RestCurve> &pull);

} // namespace camhead::cli::live
