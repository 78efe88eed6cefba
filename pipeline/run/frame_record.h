// The per-frame record of `camhead run --record-stats`: one JSON object a
// line for every frame sent to the outputs (README.md, "The live pipeline").
#pragma once

#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

namespace camhead::pipeline {

// What the record says of one composite.
struct FrameRecord {
  std::uint64_t sequence = 0;
  std::uint64_t setup = 0; // what it was rendered with: 0 as the run started, +1 per reload
  std::int64_t capture_ns = 0;
  std::int64_t exposure_mid_ns = 0;
  std::int64_t delivered_ns = 0; // when the camera handed the frame over
  std::int64_t render_start_ns = 0;
  std::int64_t render_end_ns = 0;
  double focus_m = 0.0, f_number = 0.0, focal_length_mm = 0.0;
  bool lens_fresh = false;  // the lens state covers the mid-exposure (else held or extrapolated)
  double lens_wait_s = 0.0; // how long the frame waited for it (bounded; run_loop.h)
  // The camera's pose at the mid-exposure, world metres: where the lens is,
  // its view direction and the picture's up, as the frame was rendered.
  glm::vec3 position{0.0f}, forward{0.0f, 0.0f, -1.0f}, up{0.0f, 1.0f, 0.0f};
  bool pose_fresh = false; // a tracker's pose current at that instant; a static one always
  // False before the pose source's first pose: the frame is the camera
  // image alone, and `position` and the rest are the scene's camera's.
  bool pose_known = true;
  // A marker pose's: the board's markers found in the frame, and the RMS
  // distance of the corners used from where the pose puts them (NaN: none).
  int markers_seen = 0;
  double reprojection_px = std::numeric_limits<double>::quiet_NaN();
  const char *pose_found_by = nullptr; // FramePose::found_by: a literal, or null
  // The tracker's time on the frame (NaN: not done when the frame went
  // out), and how long rendering it waited for the tracker (marker poses;
  // 0 otherwise).
  double track_s = 0.0, pose_wait_s = 0.0;
  double rpp = 0.0; // rays per pixel asked, a mean (frame_budget.h)
  std::uint64_t camera_rays = 0;
  std::uint32_t history_samples = 0;     // samples per pixel the image holds (accumulating; else 0)
  std::uint64_t reprojected_samples = 0; // of them moved from the frames before (a new history)
  double traced = 1.0;                   // the fraction of the pixels traced (the influence region)
  std::uint64_t dropped_before = 0;      // camera, render-busy and output-busy drops since the last
  double decode_s = 0.0, trace_s = 0.0, encode_s = 0.0;
  double rays_s = 0.0; // of trace_s, tracing the rays (0: not told apart)
};

// What every composite's line of a run says alike, as JSON string values
// (json_string()): the executor and where the pose comes from ("static",
// "freed:NAME", "opentrackio:NAME" with the lens source's name,
// "marker:NAME" with the marker board's).
struct RunRecordFields {
  std::string executor;
  std::string pose_source;
};

// `text` as a JSON string, quotes included.
[[nodiscard]] std::string json_string(std::string_view text);

// One line per frame sent, in the outputs' order: `output_frame` is its index
// in every output (a Y4M file's frame number). A composite's line has every
// field; a repeat or a placeholder only its kind and time.
void write_composite_record(std::FILE *out, std::uint64_t output_frame, const FrameRecord &r,
                            std::int64_t output_ns, const RunRecordFields &run);
void write_filler_record(std::FILE *out, std::uint64_t output_frame, const char *kind,
                         std::int64_t output_ns);

} // namespace camhead::pipeline
