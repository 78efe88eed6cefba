#include "marker_source.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include <glm/geometric.hpp>

#include "camhead/base/monotonic_clock.h"
#include "camhead/base/thread_name.h"
#include "luma.h"
#include "run/lens_camera.h"
#include "run/lens_hub.h"

namespace camhead::pipeline {
namespace {

constexpr std::size_t kSlots = 3;   // one tracking, two waiting
constexpr std::size_t kResults = 8; // frames the renderer may still ask about
// A pose found longer ago than this is no guide to where the board is now.
constexpr std::int64_t kFollowWithinNs = 100'000'000;

// The points whose movement in the picture the still filter measures: a
// ChArUco board's four outer corners, a field's markers' corners.
std::vector<glm::dvec3> extent_of(const MarkerBoard &board) {
  if (board.type == MarkerBoardType::charuco) {
    const double w = board.squares_x * board.square_m, h = board.squares_y * board.square_m;
    return {board_to_world(0, 0), board_to_world(w, 0), board_to_world(w, h), board_to_world(0, h)};
  }
  std::vector<glm::dvec3> corners;
  for (const PlacedMarker &m : board.markers)
    corners.insert(corners.end(), m.corners.begin(), m.corners.end());
  return corners;
}

// A frame-sized picture of `board`'s page, or of nothing where its markers
// are printed one by one (a field), for warm_up().
std::vector<std::uint8_t> warm_up_picture(const MarkerBoard &board,
                                          const base::VideoFormat &format) {
  std::vector<std::uint8_t> picture(std::size_t(format.width) * std::size_t(format.height), 128);
  if (board.type != MarkerBoardType::charuco)
    return picture;
  // The page centred, drawn at as many pixels a square (up to 32) as fit
  // four fifths of the frame.
  const int pixels_per_square = std::clamp(
      std::min(4 * format.width / (5 * board.squares_x), 4 * format.height / (5 * board.squares_y)),
      1, 32);
  const BoardPage page = draw_board_page(board, pixels_per_square);
  const int w = std::min(page.width, format.width), h = std::min(page.height, format.height);
  const int x0 = (format.width - w) / 2, y0 = (format.height - h) / 2;
  for (int y = 0; y < h; ++y)
    std::copy_n(page.grey.begin() + std::ptrdiff_t(y) * page.width, w,
                picture.begin() + std::ptrdiff_t(y0 + y) * format.width + x0);
  return picture;
}

} // namespace

// The next frame is a whole frame interval past the newest pose found, and
// extrapolating only part of the way leaves the rest of the camera's motion
// in the picture (the moving rig's found frames, each predicted as if it
// were late: median 1.10 px at the virtual objects with 20 ms of a 40-ms
// interval, 0.39 px with all of it; bench/RESULTS.md, "Late frames and the
// first"). Two intervals cover a second late frame in a row; found poses
// with one frame missed between them still give the motion.
PoseTimelineParams predicted_pose_params(std::int64_t frame_interval_ns) {
  PoseTimelineParams p;
  p.max_extrapolation_ns = 2 * frame_interval_ns;
  p.stale_after_ns = 2 * frame_interval_ns + frame_interval_ns / 2;
  return p;
}

CameraModel tracker_camera(const lens_control::LensState &lens, const base::VideoFormat &format,
                           double sensor_width_mm) {
  CameraModel camera;
  camera.fx = camera.fy =
      lens.projection_focal_length_mm.value * double(format.width) / sensor_width_mm;
  // The renderer's pixel x spans [x, x + 1); OpenCV's is centred on x.
  const renderer::LensModel model = lens_model(lens);
  camera.fy = camera.fx * double(model.fy_over_fx);
  camera.cx = double(model.principal_point.x) * format.width - 0.5;
  camera.cy = double(model.principal_point.y) * format.height - 0.5;
  camera.distortion = {model.k1, model.k2, model.p1, model.p2, model.k3};
  // The renderer's thin lens (renderer/src/compiled_scene.cpp): an aperture
  // f / N across, focused at S, spreads a point at depth z over
  // f / N * fx * |1/S - 1/z| pixels. The tracker draws the board so blurred
  // where it cannot read it.
  const double f_m = lens.focal_length_mm.value * 1e-3, n = lens.f_number.value;
  if (f_m > 0.0 && n > 0.0 && lens.focus_distance_m.value > 0.0) {
    camera.focus_m = lens.focus_distance_m.value;
    camera.defocus_px = f_m / n * camera.fx;
  }
  return camera;
}

TrackerGuides tracker_guides(const PoseTimeline &found, std::int64_t mid_ns) {
  TrackerGuides guides;
  if (found.size() == 0 || mid_ns - found.newest_ns() > kFollowWithinNs)
    return guides;
  guides.predicted = found.at(mid_ns)->pose;
  if (mid_ns > found.newest_ns())
    guides.newest = found.at(found.newest_ns())->pose;
  return guides;
}

MarkerPose track_guided(MarkerTracker &tracker, const LumaImage &luma, const CameraModel &camera,
                        const TrackerGuides &guides, double pupil_m) {
  const auto at_pupil = [pupil_m](CameraPose pose) {
    pose.position += pose.forward() * pupil_m;
    return pose;
  };
  std::optional<CameraPose> guide;
  if (guides.predicted)
    guide = at_pupil(*guides.predicted);
  MarkerPose found = tracker.track(luma, camera, guide ? &*guide : nullptr);
  if (!found.found && guides.newest) {
    guide = at_pupil(*guides.newest);
    const int markers_seen = found.markers_seen;
    found = tracker.track(luma, camera, &*guide);
    found.markers_seen = std::max(found.markers_seen, markers_seen);
  }
  if (found.found)
    found.pose.position -= found.pose.forward() * pupil_m;
  return found;
}

MarkerPoseSource::MarkerPoseSource(const MarkerBoard &board, const base::VideoFormat &format,
                                   const renderer::FrameCamera &base, const LensHub &lens,
                                   bool every_frame, std::int64_t lens_wait_ns,
                                   std::int64_t frame_interval_ns)
    : tracker_(open_marker_tracker(board)), format_(format), sensor_width_mm_(base.sensor_width_mm),
      lens_(lens), every_frame_(every_frame), lens_wait_ns_(lens_wait_ns),
      name_("marker:" + board.name), slots_(kSlots), results_(kResults),
      found_(predicted_pose_params(frame_interval_ns)), board_(board),
      board_extent_(extent_of(board)) {
  for (Slot &slot : slots_)
    slot.luma.resize(std::size_t(format.width) * std::size_t(format.height));
}

MarkerPoseSource::~MarkerPoseSource() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  work_.notify_all();
  freed_.notify_all();
  if (thread_.joinable())
    thread_.join();
}

void MarkerPoseSource::start() {
  if (!thread_.joinable())
    thread_ = std::thread([this] {
      base::name_this_thread("camhead-track");
      warm_up();
      track_loop();
    });
}

// OpenCV pays its one-time set-up in the first detection: the first frame
// of a run tracked in 12-16 ms against 3-4 ms for the next, and in one run
// came past its deadline with no pose yet to predict from
// (bench/RESULTS.md, "The first frame's tracking"). A picture of the board
// tracked once before the first frame pays it instead; the pose is dropped.
void MarkerPoseSource::warm_up() {
  try {
    const std::vector<std::uint8_t> picture = warm_up_picture(board_, format_);
    CameraModel camera;
    camera.fx = camera.fy = format_.width;
    camera.cx = 0.5 * format_.width;
    camera.cy = 0.5 * format_.height;
    (void)tracker_->track({picture.data(), format_.width, format_.height,
                           std::ptrdiff_t(format_.width), luma_limited_range(format_)},
                          camera, nullptr);
  } catch (const std::exception &) {
    // Only the first frame's time is at stake.
  }
}

void MarkerPoseSource::submit(const hal::camera::CapturedFrame &frame) {
  if (frame.format.width != format_.width || frame.format.height != format_.height)
    return;
  Slot *slot = nullptr;
  {
    std::unique_lock lock(mutex_);
    const auto find_free = [&] {
      for (Slot &s : slots_)
        if (s.state == SlotState::free)
          return &s;
      return static_cast<Slot *>(nullptr);
    };
    if (every_frame_)
      freed_.wait(lock, [&] { return stop_ || find_free() != nullptr; });
    slot = find_free();
    if (slot == nullptr) // every slot waiting or tracking: the oldest waiting one gives way
      for (Slot &s : slots_)
        if (s.state == SlotState::waiting && (slot == nullptr || s.sequence < slot->sequence))
          slot = &s;
    if (slot == nullptr)
      return;
    slot->state = SlotState::filling;
  }
  copy_luma(frame.format, frame.bytes, slot->luma);
  {
    const std::lock_guard lock(mutex_);
    slot->sequence = frame.sequence;
    slot->mid_ns = hal::camera::mid_exposure_ns(frame);
    slot->submitted_ns = base::monotonic_ns();
    slot->state = SlotState::waiting;
  }
  work_.notify_one();
}

void MarkerPoseSource::track_loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    work_.wait(lock, [this] {
      return stop_ || std::any_of(slots_.begin(), slots_.end(),
                                  [](const Slot &s) { return s.state == SlotState::waiting; });
    });
    if (stop_)
      return;
    // Live, the newest frame, and the ones before it are not tracked (the
    // renderer skips them too when it is behind); offline, the oldest.
    Slot *slot = nullptr;
    for (Slot &s : slots_)
      if (s.state == SlotState::waiting &&
          (slot == nullptr ||
           (every_frame_ ? s.sequence < slot->sequence : s.sequence > slot->sequence)))
        slot = &s;
    if (!every_frame_)
      for (Slot &s : slots_)
        if (s.state == SlotState::waiting && &s != slot) {
          results_[next_result_++ % kResults] = {s.sequence, false, {}};
          s.state = SlotState::free;
        }
    slot->state = SlotState::tracking;
    // The poses found recently enough to follow the board from.
    const TrackerGuides guides = tracker_guides(found_, slot->mid_ns);
    lock.unlock();

    // The markers see from the entrance pupil; the renderer's camera, the
    // still filter and the history of poses are the lens's reference plane,
    // which stays put while focusing moves the pupil.
    const lens_control::LensState lens =
        lens_.state_when_covered(slot->mid_ns, slot->submitted_ns + lens_wait_ns_ / 2, &stop_)
            .state;
    const LumaImage luma{slot->luma.data(), format_.width, format_.height,
                         std::ptrdiff_t(format_.width), luma_limited_range(format_)};
    const CameraModel camera = tracker_camera(lens, format_, sensor_width_mm_);
    const std::int64_t track_start_ns = base::monotonic_ns();
    MarkerPose found =
        track_guided(*tracker_, luma, camera, guides, lens.entrance_pupil_offset_mm.value / 1000.0);
    const double track_s = double(base::monotonic_ns() - track_start_ns) * 1e-9;
    if (found.found)
      found.pose = still_.filter(found.pose, camera.fx, board_extent_);

    lock.lock();
    results_[next_result_++ % kResults] = {slot->sequence, true, found, track_s};
    if (found.found)
      (void)found_.push(slot->mid_ns, found.pose);
    slot->state = SlotState::free;
    done_.notify_all();
    freed_.notify_all();
  }
}

const MarkerPoseSource::Result *MarkerPoseSource::result_of(std::uint64_t sequence) const {
  for (const Result &r : results_)
    if (r.sequence == sequence)
      return &r;
  return nullptr;
}

FramePose MarkerPoseSource::pose_for(std::uint64_t sequence, std::int64_t mid_exposure_ns,
                                     std::int64_t deadline_ns, const CameraPose &rest) {
  const std::int64_t wait_start_ns = base::monotonic_ns();
  std::unique_lock lock(mutex_);
  const auto deadline =
      std::chrono::steady_clock::time_point(std::chrono::nanoseconds(deadline_ns));
  (void)done_.wait_until(lock, deadline, [&] { return result_of(sequence) != nullptr; });
  FramePose out;
  out.wait_s = double(base::monotonic_ns() - wait_start_ns) * 1e-9;
  const Result *result = result_of(sequence);
  if (result == nullptr)
    out.track_s = std::numeric_limits<double>::quiet_NaN(); // still tracking, or not yet begun
  if (result != nullptr && result->tracked) {
    out.markers_seen = result->pose.markers_seen;
    out.track_s = result->track_s;
    if (result->pose.found) {
      out.pose = result->pose.pose;
      out.fresh = true;
      out.known = true;
      out.reprojection_px = result->pose.reprojection_px;
      out.found_by = result->pose.aligned    ? "alignment"
                     : result->pose.followed ? "corners"
                                             : "markers";
      return out;
    }
  }
  const std::optional<PoseAt> predicted = found_.at(mid_exposure_ns);
  // A frame earlier than every pose found (one a later frame's, tracked
  // first) is before the first pose, whatever order the frames were
  // tracked in: a take composited offline gives the same frames each time.
  // Its pose is the stand-in, as LensHub::pose_at gives a tracker's.
  out.known = predicted && !predicted->before_first;
  out.pose = out.known ? predicted->pose : rest;
  return out;
}

} // namespace camhead::pipeline
