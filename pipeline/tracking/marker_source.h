// The marker pose source in the live pipeline: each camera frame's pose,
// found in that frame's own picture (marker_tracker.h) on a thread of its
// own while the frame before renders, so that there is no tracking delay to
// calibrate, and never holding the output.
//
//   capture thread   submit(frame): the luma plane copied into a free slot
//                    (the camera's buffer goes back at once); never waits
//   camhead-track    first tracks a picture of the board once (OpenCV's
//                    set-up, paid before the first frame), then
//                    tracks the newest frame handed over, with the lens at
//                    its mid-exposure (focal length in pixels from the
//                    profile's projection focal length: breathing and zoom
//                    followed), holds it while the camera is still
//                    (still_pose.h), and keeps the result
//   render thread    pose_for(frame): that frame's result, waiting for it at
//                    most until a deadline; when it is late or the board was
//                    not seen, the pose predicted from the frames before
//                    (predicted_pose_params: the last two found poses'
//                    motion, for up to two frame intervals, then held),
//                    flagged not fresh
//
// The found pose is the entrance pupil's (the pinhole of the model the
// markers are solved with); the renderer's camera is the lens's reference
// plane, the profile's entrance-pupil offset behind it, which stays put
// while focusing moves the pupil: the still filter and the poses kept are
// the reference plane's.
//
// The slots and the results are made at construction: submit() copies into
// a slot, and pose_for() allocates nothing (the render thread's allocations
// are counted in tests/markers). The tracking thread runs OpenCV, which
// allocates as it detects: it holds no frame and no output waits on it.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "camhead/base/video_format.h"
#include "camhead/hal/camera/camera_source.h"
#include "camhead/lens_control/lens_state.h"
#include "camhead/renderer/frame_camera.h"
#include "marker_tracker.h"
#include "pose_timeline.h"
#include "still_pose.h"

namespace camhead::pipeline {

class LensHub;

// How a frame whose own pose is late or not found is predicted from the
// poses found, for a camera of `frame_interval_ns`: along the last two, for
// up to two frame intervals, then held.
[[nodiscard]] PoseTimelineParams predicted_pose_params(std::int64_t frame_interval_ns);

// The poses that guide the tracker into a frame (marker_tracker.h), from
// the poses found before it (reference-plane poses, as found_ keeps them):
// the pose they predict for the frame's mid-exposure, and the newest found
// as it was, where the prediction went past it. Neither where the newest
// is older than 100 ms: no guide to where the board is now.
struct TrackerGuides {
  std::optional<CameraPose> predicted, newest;
};
[[nodiscard]] TrackerGuides tracker_guides(const PoseTimeline &found, std::int64_t mid_ns);

// The frame's pose: tracked from the predicted guide, and where that finds
// nothing, from the newest found as it was. A camera that turns back
// between two frames (a dolly stopped hard, a whip pan's end) is where the
// prediction overshoots by twice a frame's motion: at 10 fps on the moving
// rig's test, far enough that the board blurred past reading was not
// aligned from it, and then never again. Guides and pose are the
// reference plane's; `pupil_m`: the entrance pupil ahead of it, where the
// tracker sees from.
[[nodiscard]] MarkerPose track_guided(MarkerTracker &tracker, const LumaImage &luma,
                                      const CameraModel &camera, const TrackerGuides &guides,
                                      double pupil_m);

// The lens as the tracker models it, in pixels of a frame of `format`
// whose width spans `sensor_width_mm` of the sensor the lens projects onto.
[[nodiscard]] CameraModel tracker_camera(const lens_control::LensState &lens,
                                         const base::VideoFormat &format, double sensor_width_mm);

// What a frame's pose was, for the renderer and the record.
struct FramePose {
  CameraPose pose;
  bool fresh = false; // found in this very frame
  bool known = false; // found at or before this instant (else `pose` is the scene's camera)
  int markers_seen = 0;
  double reprojection_px = std::numeric_limits<double>::quiet_NaN(); // NaN: not found
  // How the tracker found it: "markers" (read), "corners" (followed from
  // the pose before), "alignment" (the whole board drawn blurred and
  // aligned: marker_tracker.h); null when not found in the frame.
  const char *found_by = nullptr;
  // The tracker's time on this frame (0: left for a newer frame; NaN: not
  // done by the frame's deadline, so not known when it went out), and how
  // long the render thread waited for it in pose_for(): the latency
  // tracking adds.
  double track_s = 0.0, wait_s = 0.0;
};

class MarkerPoseSource {
public:
  // Opens the tracking module for `board` (throws MarkerModuleError) and
  // makes the slots for frames of `format`. `base`: the sensor the lens
  // projects onto (its width in millimetres). `every_frame`: a take
  // composited offline, where every frame is rendered: each is tracked, in
  // order, and submit() waits for a free slot; live, a tracker that falls
  // behind tracks the newest frame and leaves the ones before it. Each
  // frame is tracked through the lens of its mid-exposure, waited for as
  // the renderer waits (LensHub::state_when_covered): a frame tracked
  // through a lens the rig did not have (the profile's rest state, before
  // the first readings) is a pose off by the lens's breathing and pupil
  // shift. `lens_wait_ns`: how long the render thread waits for the lens
  // and for the pose after a frame is handed over; the tracker waits for
  // the lens half of it at most, leaving the rest for the tracking.
  // `frame_interval_ns`: the camera's, how far ahead a late frame's pose
  // is predicted.
  MarkerPoseSource(const MarkerBoard &board, const base::VideoFormat &format,
                   const renderer::FrameCamera &base, const LensHub &lens, bool every_frame,
                   std::int64_t lens_wait_ns, std::int64_t frame_interval_ns);
  ~MarkerPoseSource();
  MarkerPoseSource(const MarkerPoseSource &) = delete;
  MarkerPoseSource &operator=(const MarkerPoseSource &) = delete;

  void start(); // the tracking thread
  // Capture thread: hands a frame over. A frame of another size than the
  // one made for is not tracked (its pose will be predicted). Live, it
  // never waits (the oldest frame not yet tracked gives way).
  void submit(const hal::camera::CapturedFrame &frame);
  // Render thread: frame `sequence`'s pose; waits for the tracker until
  // `deadline_ns` (CLOCK_MONOTONIC) at most. `rest`: the pose before any was
  // found.
  [[nodiscard]] FramePose pose_for(std::uint64_t sequence, std::int64_t mid_exposure_ns,
                                   std::int64_t deadline_ns, const CameraPose &rest);
  // "marker:NAME".
  [[nodiscard]] const std::string &name() const { return name_; }

private:
  enum class SlotState { free, filling, waiting, tracking };
  struct Slot {
    SlotState state = SlotState::free;
    std::uint64_t sequence = 0;
    std::int64_t mid_ns = 0;
    std::int64_t submitted_ns = 0; // CLOCK_MONOTONIC, when the frame was handed over
    std::vector<std::uint8_t> luma;
  };
  struct Result {
    std::uint64_t sequence = std::numeric_limits<std::uint64_t>::max();
    bool tracked = false; // false: skipped for a newer frame
    MarkerPose pose;
    double track_s = 0.0;
  };

  void warm_up();
  void track_loop();
  [[nodiscard]] const Result *result_of(std::uint64_t sequence) const;

  std::unique_ptr<MarkerTracker> tracker_;
  const base::VideoFormat format_;
  const double sensor_width_mm_;
  const LensHub &lens_;
  const bool every_frame_;
  const std::int64_t lens_wait_ns_;
  std::string name_;

  std::mutex mutex_;
  std::condition_variable work_, done_, freed_;
  std::vector<Slot> slots_;
  std::vector<Result> results_; // a ring, by sequence
  std::size_t next_result_ = 0;
  PoseTimeline found_; // the poses found: the tracker's guide, and frames without one
  StillPoseFilter still_;
  const MarkerBoard board_;
  std::vector<glm::dvec3> board_extent_; // for the still filter
  std::atomic<bool> stop_{false};        // set under mutex_; read unlocked by the lens wait
  std::thread thread_;
};

} // namespace camhead::pipeline
