// Pose traces: a camera's path as a CSV file, the pose twin of the lens
// trace (hal/lens/trace/README.md): the simulated camera plays it (board
// `camera.path`), and a board can take its pose from it (`pose.type`
// "trace": a perfect tracker, the truth of the simulated rig).
//
//   # camhead pose trace v1
//   t_s,x_m,y_m,z_m,pan_deg,tilt_deg,roll_deg
//   0,0,1.2,3,0,-10,0
//   4,0.5,1.2,2.5,8,-12,0
//
// Positions in the scene's world (metres, y up); the camera at pan, tilt
// and roll 0 looks along -z with its picture upright; pan turns it to the
// right (clockwise seen from above), then tilt up, then roll clockwise as
// seen from behind: a camera head's own axes (as FreeD's). Between rows the
// pose is interpolated (position linearly, rotation along the shortest
// arc). The trace plays in a loop of t_last - t_first seconds with its time
// 0 at CLOCK_MONOTONIC 0, so that the simulated camera, the board's pose and
// a test all know the camera at any instant; end a path where it starts.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include "camera_pose.h"
#include "camhead/base/config_error.h"

namespace camhead::pipeline {

class PoseTraceError : public base::ConfigError {
public:
  using base::ConfigError::ConfigError;
  explicit PoseTraceError(const base::ConfigError &e) : base::ConfigError(e) {}
};

class PoseTrace {
public:
  struct Row {
    std::int64_t t_ns = 0;
    CameraPose pose;
  };
  explicit PoseTrace(std::vector<Row> rows); // at least two, time strictly increasing

  // The pose at CLOCK_MONOTONIC instant t_ns.
  [[nodiscard]] CameraPose at(std::int64_t t_ns) const;
  [[nodiscard]] const std::vector<Row> &rows() const { return rows_; }

private:
  std::vector<Row> rows_;
};

// The camera pose of one row's values (the axes above).
[[nodiscard]] CameraPose pose_of_row(double x_m, double y_m, double z_m, double pan_deg,
                                     double tilt_deg, double roll_deg);

// Throws PoseTraceError("FILE:LINE: FIELD: REASON").
[[nodiscard]] PoseTrace parse_pose_trace(std::string_view text, const std::filesystem::path &file);
[[nodiscard]] PoseTrace load_pose_trace(const std::filesystem::path &file);

} // namespace camhead::pipeline
