// libcamhead_markers.so (tracking/marker_tracker.h): the marker pose source
// on OpenCV 4.6's aruco, calib3d and video (ECC). Its one exported symbol is
// the factory (marker_module_abi.h); everything else is hidden.
//
// Per picture: the board's markers are detected on the luma plane decoded to
// light (a table lookup a pixel, light_table; no colour conversion); a
// ChArUco board's chessboard corners are interpolated from them with the
// frame's lens (so that a distorting lens does not bend the homography,
// opencv issue 23873) and refined to sub-pixel; a field gives its markers'
// four corners. The pose is solved from the corners: IPPE for a planar
// target (which gives both poses of the planar ambiguity, opencv issue
// 8813), SQPnP for a field that is not flat, then refined by
// Levenberg-Marquardt on all points. A ChArUco board blurred past reading is
// followed from the pose before: its corners, or the whole board drawn with
// the lens's blur and aligned (board_aligner.h).
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <opencv2/aruco.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "../marker_module_abi.h"
#include "board_aligner.h"
#include "camera_calibrator.h"
#include "code_to_light.h"

namespace camhead::pipeline {
namespace {

// Two planar poses whose reprojection errors are this close are both
// plausible: the frame is ambiguous.
constexpr double kAmbiguousRatio = 0.7;
// Four points determine a plane's pose; six give it some redundancy.
constexpr std::size_t kMinPoints = 6;
// A corner followed from the previous pose: found within this fraction of
// the board's square (in pixels) of where that pose puts it, in a window
// whose pixels spread by at least this much (standard deviation, digital
// numbers).
constexpr double kFollowReach = 0.3, kFollowContrast = 12.0;
// At least this many followed corners, fitting one pose this well.
constexpr std::size_t kMinFollowed = 10;
constexpr double kMaxFollowedReprojectionPx = 1.0;
// A chessboard corner is looked for where the pose of all the markers read
// puts it, and kept with one of its (up to two) neighbouring markers read,
// not OpenCV's default two: on a defocused or distant board, where only
// some codes are readable, the default keeps a few corners of many (2-7 of
// 17-21 on the moving rig's board with 8-9 of 17 markers read, too few to
// solve from), and every one of them is refined on the image all the same.
constexpr int kMinAdjacentMarkers = 1;
// Half the side of the window a chessboard corner is refined in, pixels.
constexpr int kMinRefineHalfWindow = 2, kMaxRefineHalfWindow = 8;
// A followed corner's window: a fifth of the square on each side (at most
// 24 px). A third reached into the markers' blurred edges, whose pull left
// the moving rig's followed corners 2.2-3.5 px RMS off one board (all
// refused); a fifth fits them within 1 px and halves the synthetic board's
// error at 4-6 px of blur; at an eighth the blurred X fills the window and
// noise wins (bench/RESULTS.md, "Registration by blur").
constexpr float kFollowWindow = 1.0f / 5.0f;
constexpr int kMaxFollowHalfWindow = 24;
constexpr double kNoLimit = std::numeric_limits<double>::infinity();
// A board blurred by this much is aligned whole first (board_aligner.h):
// from 2 px on, that is nearer the truth than its corners read or followed
// in a noisy picture (the moving rig: 0.19 px median, 0.35 px p90 at 2-3
// px, against 0.51 and 0.83 px read), and no worse than 0.2 px in a clean
// one (bench/RESULTS.md, "the page's resolution"); the pose kept if the
// corners the alignment gives fit it this well.
constexpr double kAlignFromBlurPx = 2.0;
constexpr double kMaxAlignedReprojectionPx = 1.0;

cv::Matx33d camera_matrix(const CameraModel &c) {
  return {c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0};
}

// The camera pose in the world from OpenCV's (rvec, tvec) of the target's
// points, and the target's frame in the world (`to_world`, a rotation).
CameraPose world_pose(const cv::Vec3d &rvec, const cv::Vec3d &tvec, const glm::dmat3 &to_world) {
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  const cv::Matx33d rt = r.t();
  const cv::Vec3d centre = -(rt * tvec);
  // OpenCV's camera: x right, y down, z ahead; camhead's: x right, y up,
  // looking along -z. Columns of R^T are the camera's axes in the target's
  // frame.
  const glm::dvec3 x(rt(0, 0), rt(1, 0), rt(2, 0));
  const glm::dvec3 y(rt(0, 1), rt(1, 1), rt(2, 1));
  const glm::dvec3 z(rt(0, 2), rt(1, 2), rt(2, 2));
  const glm::dmat3 axes(to_world * x, to_world * -y, to_world * -z);
  return {to_world * glm::dvec3(centre[0], centre[1], centre[2]),
          glm::normalize(glm::quat_cast(axes))};
}

// OpenCV's (rvec, tvec) of the target's points for a camera at `pose` in
// the world: world_pose() undone.
void extrinsics(const CameraPose &pose, const glm::dmat3 &to_world, cv::Vec3d &rvec,
                cv::Vec3d &tvec) {
  const glm::dmat3 axes = glm::mat3_cast(pose.orientation); // right, up, back in the world
  const glm::dmat3 from_world = glm::transpose(to_world);
  const glm::dvec3 x = from_world * axes[0], y = from_world * -axes[1],
                   z = from_world * -axes[2]; // OpenCV's camera axes in the target's frame
  const cv::Matx33d r(x.x, x.y, x.z, y.x, y.y, y.z, z.x, z.y, z.z);
  const glm::dvec3 c = from_world * pose.position;
  tvec = -(r * cv::Vec3d(c.x, c.y, c.z));
  cv::Rodrigues(r, rvec);
}

// How far apart two orientations are, radians.
double angle_between(const glm::dquat &a, const glm::dquat &b) {
  return 2.0 * std::acos(std::min(1.0, std::abs(glm::dot(a, b))));
}

// The spread of the points along their three principal axes, largest
// first (variances, square metres).
cv::Vec3f spread(const std::vector<cv::Point3f> &points) {
  cv::Mat data(int(points.size()), 3, CV_32F, const_cast<cv::Point3f *>(points.data()));
  cv::PCA pca(data, cv::Mat(), cv::PCA::DATA_AS_ROW);
  return {pca.eigenvalues.at<float>(0), pca.eigenvalues.at<float>(1), pca.eigenvalues.at<float>(2)};
}

class OpenCvTracker final : public MarkerTracker {
public:
  explicit OpenCvTracker(const MarkerBoard &board)
      : board_(board), dictionary_(cv::aruco::getPredefinedDictionary(board.dictionary)),
        parameters_(cv::aruco::DetectorParameters::create()), to_light_{light_table(false, CV_32F),
                                                                        light_table(true, CV_32F)},
        to_light8_{light_table(false, CV_8U), light_table(true, CV_8U)} {
    // One core: the tracker runs beside the renderer, which has the others.
    // (A process-wide setting; this module is camhead's only OpenCV user.)
    cv::setNumThreads(1);
    // The detector thresholds the picture once per window size, 3, 13 and
    // 23 px by default; the third pass cost a third of the time and changed
    // no pose in tests/markers (bench/RESULTS.md: 4.5 -> 2.9 ms at 720x576,
    // 12.8 -> 8.2 ms at 1920x1080).
    parameters_->adaptiveThreshWinSizeMax = 13;
    if (board.type == MarkerBoardType::charuco) {
      charuco_ =
          cv::aruco::CharucoBoard::create(board.squares_x, board.squares_y, float(board.square_m),
                                          float(board.marker_m), dictionary_);
      // Board coordinates (x right, y down the page, z into it) in the
      // world: marker_board.h.
      to_world_ = glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0));
      aligner_.emplace(board, charuco_);
    } else {
      parameters_->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
    }
  }

  MarkerPose track(const LumaImage &luma, const CameraModel &camera,
                   const CameraPose *previous) override {
    try {
      return track_or_throw(luma, camera, previous);
    } catch (const std::exception &) {
      return {}; // OpenCV refused the picture: no pose from it
    }
  }

private:
  MarkerPose track_or_throw(const LumaImage &luma, const CameraModel &camera,
                            const CameraPose *previous) {
    const cv::Mat codes(luma.height, luma.width, CV_8UC1, const_cast<std::uint8_t *>(luma.data),
                        std::size_t(luma.stride));
    // The markers and corners are read in light, to 8 bits (light_table);
    // the aligner decodes the codes itself, to floats.
    const int range = luma.limited_range ? 1 : 0;
    cv::LUT(codes, to_light8_[range], light_);
    const cv::Mat &image = light_;
    const cv::Matx33d k = camera_matrix(camera);
    const cv::Mat distortion(camera.distortion, false);
    object_.clear();
    image_points_.clear();
    // A board blurred by kAlignFromBlurPx or more where the pose before
    // puts it is aligned whole first, and its markers are not looked for.
    cv::Vec3d rvec, tvec;
    if (previous != nullptr)
      extrinsics(*previous, to_world_, rvec, tvec);
    double blur = aligner_ && previous != nullptr
                      ? aligner_->board_blur(camera, k, distortion, rvec, tvec, image.size())
                      : 0.0;
    // The board aligned from (rvec, tvec), blurred by `blur`, into
    // `aligned`; `guide`: the pose that picks between a flip's two poses.
    MarkerPose aligned;
    bool tried_aligning = false;
    const auto align = [&](const MarkerPose &so_far, const CameraPose *guide) {
      tried_aligning = true;
      aligned = so_far;
      aligned.followed = aligned.ambiguous = false;
      aligned.aligned = true;
      return aligner_->align(codes, to_light_[range], k, distortion, rvec, tvec, blur, object_,
                             image_points_) &&
             solve(aligned, k, distortion, guide, kMaxAlignedReprojectionPx);
    };
    if (blur >= kAlignFromBlurPx && align(MarkerPose{}, previous))
      return aligned;

    corners_.clear();
    ids_.clear();
    cv::aruco::detectMarkers(image, dictionary_, corners_, ids_, parameters_);
    MarkerPose out;
    following_ = false;
    if (charuco_) {
      out.markers_seen = int(ids_.size());
      charuco_corners_.clear();
      charuco_ids_.clear();
      if (!ids_.empty()) {
        cv::aruco::interpolateCornersCharuco(corners_, ids_, image, charuco_, charuco_corners_,
                                             charuco_ids_, k, distortion, kMinAdjacentMarkers);
        refine_chessboard_corners(image);
      }
      // Few corners read from the markers: follow the board from the
      // previous pose instead, where that finds more.
      if (charuco_ids_.size() < kMinFollowed && previous != nullptr) {
        read_corners_.swap(charuco_corners_);
        read_ids_.swap(charuco_ids_);
        follow_corners(image, k, distortion, *previous);
        if (charuco_ids_.size() < read_ids_.size()) {
          read_corners_.swap(charuco_corners_);
          read_ids_.swap(charuco_ids_);
          following_ = false;
        }
      }
      for (std::size_t i = 0; i < charuco_ids_.size(); ++i) {
        object_.push_back(charuco_->chessboardCorners[std::size_t(charuco_ids_[i])]);
        image_points_.push_back(charuco_corners_[i]);
      }
    } else {
      for (std::size_t i = 0; i < ids_.size(); ++i) {
        const auto placed = std::find_if(board_.markers.begin(), board_.markers.end(),
                                         [&](const PlacedMarker &m) { return m.id == ids_[i]; });
        if (placed == board_.markers.end())
          continue; // a marker of the dictionary that is not the field's
        ++out.markers_seen;
        for (int c = 0; c < 4; ++c) {
          const glm::dvec3 &p = placed->corners[std::size_t(c)];
          object_.emplace_back(float(p.x), float(p.y), float(p.z));
          image_points_.push_back(corners_[i][std::size_t(c)]);
        }
      }
    }
    out.followed = following_;
    if (solve(out, k, distortion, previous, following_ ? kMaxFollowedReprojectionPx : kNoLimit)) {
      // Read without a pose before (the board's first frame, or its first
      // after being lost): where the pose read puts the board blurred by
      // kAlignFromBlurPx or more, the board is aligned whole from it, as
      // it would have been with a pose before. The moving rig's first
      // frame, read from 4 markers at 6.3 px of blur, was 2.6 px off; every
      // aligned frame after it, 0.2 px.
      if (aligner_ && previous == nullptr) {
        extrinsics(out.pose, to_world_, rvec, tvec);
        blur = aligner_->board_blur(camera, k, distortion, rvec, tvec, image.size());
        if (blur >= kAlignFromBlurPx && align(out, &out.pose))
          return aligned;
      }
      return out;
    }
    // Nothing read, nothing followed: the whole board, aligned.
    if (aligner_ && previous != nullptr && !tried_aligning && align(out, previous))
      return aligned;
    return out;
  }

  // The pose from object_ and image_points_ into `out`, if they give one
  // that fits them within `max_reprojection_px` RMS.
  bool solve(MarkerPose &out, const cv::Matx33d &k, const cv::Mat &distortion,
             const CameraPose *previous, double max_reprojection_px) {
    out.points_used = int(object_.size());
    if (object_.size() < kMinPoints)
      return false;
    // Points on one line (a ChArUco strip one corner wide, the one row of a
    // board seen) leave the turn about that line free: no pose.
    const cv::Vec3f s = spread(object_);
    if (s[1] <= 1e-6f * s[0])
      return false;

    std::vector<cv::Vec3d> rvecs, tvecs;
    std::vector<double> errors;
    const bool planar = charuco_ || s[2] <= 1e-8f * std::max(1.0f, s[0]);
    cv::solvePnPGeneric(object_, image_points_, k, distortion, rvecs, tvecs, false,
                        planar ? cv::SOLVEPNP_IPPE : cv::SOLVEPNP_SQPNP, cv::noArray(),
                        cv::noArray(), errors);
    if (rvecs.empty())
      return false;
    std::size_t chosen = 0;
    if (rvecs.size() > 1 && errors.size() > 1 && errors[1] > 0.0 &&
        errors[0] / errors[1] > kAmbiguousRatio) {
      out.ambiguous = true;
      if (previous != nullptr) {
        const auto distance = [&](std::size_t i) {
          return angle_between(world_pose(rvecs[i], tvecs[i], to_world_).orientation,
                               previous->orientation);
        };
        chosen = distance(1) < distance(0) ? 1 : 0;
      }
    }
    cv::Vec3d rvec = rvecs[chosen], tvec = tvecs[chosen];
    cv::solvePnPRefineLM(object_, image_points_, k, distortion, rvec, tvec);
    cv::projectPoints(object_, rvec, tvec, k, distortion, projected_);
    double sum = 0.0;
    for (std::size_t i = 0; i < projected_.size(); ++i) {
      const cv::Point2f d = projected_[i] - image_points_[i];
      sum += double(d.dot(d));
    }
    out.reprojection_px = std::sqrt(sum / double(projected_.size()));
    if (!std::isfinite(out.reprojection_px) || !std::isfinite(cv::norm(rvec)) ||
        !std::isfinite(cv::norm(tvec)))
      return false; // a solve that did not converge
    if (out.reprojection_px > max_reprojection_px)
      return false; // the followed corners do not make one board: not it
    out.pose = world_pose(rvec, tvec, to_world_);
    out.found = true;
    return true;
  }

  // interpolateCornersCharuco refines each corner in one fixed window and
  // stops at 0.1 px. A chessboard corner is an unbiased saddle only while
  // its window holds nothing else: the markers sit a margin away, which a
  // board seen at a slant squeezes to a few pixels across the slant. Each
  // corner is refined again in the largest window that stays clear of the
  // detected markers' corners, to a thousandth of a pixel.
  void refine_chessboard_corners(const cv::Mat &image) {
    for (cv::Point2f &corner : charuco_corners_) {
      float clear = std::numeric_limits<float>::max();
      for (const std::vector<cv::Point2f> &marker : corners_)
        for (const cv::Point2f &m : marker)
          clear = std::min(clear, std::max(std::abs(m.x - corner.x), std::abs(m.y - corner.y)));
      const int half = std::clamp(int(clear) - 1, kMinRefineHalfWindow, kMaxRefineHalfWindow);
      refined_.assign(1, corner);
      cv::cornerSubPix(
          image, refined_, cv::Size(half, half), cv::Size(-1, -1),
          cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 0.001));
      corner = refined_.front();
    }
  }

  // A defocused or moving board keeps its chessboard corners (a blurred X
  // stays an X, centred where it was) long after its markers' codes are
  // unreadable (bench/RESULTS.md: from about 3 px of blur on a 5x5 marker
  // of 26 px). With too few corners found from the markers, each corner is
  // looked for where the previous pose puts it, refined in a window of
  // kFollowWindow of a square, and kept only if it stayed within kFollowReach of a
  // square of there (so that it cannot jump to its neighbour) in a window
  // with contrast; the corners kept must make one board (the reprojection
  // check in track_or_throw). The camera must move less than that between
  // frames; the pose is then flagged `followed`.
  void follow_corners(const cv::Mat &image, const cv::Matx33d &k, const cv::Mat &distortion,
                      const CameraPose &previous) {
    following_ = false;
    cv::Vec3d rvec, tvec;
    extrinsics(previous, to_world_, rvec, tvec);
    cv::projectPoints(charuco_->chessboardCorners, rvec, tvec, k, distortion, predicted_);
    charuco_corners_.clear();
    charuco_ids_.clear();
    const std::size_t n = predicted_.size();
    if (n < kMinFollowed)
      return; // a board too small to follow
    for (std::size_t i = 0; i < n; ++i) {
      const cv::Point2f p = predicted_[i];
      const float square = float(
          cv::norm(predicted_[corner_neighbour(i, std::size_t(board_.squares_x - 1), n)] - p));
      // A corner the pose puts nowhere (behind the camera, or a projection
      // that overflowed) is not looked for; nor one too near the edge.
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(square))
        continue;
      const int half =
          std::clamp(int(std::min(square * kFollowWindow, float(kMaxFollowHalfWindow))),
                     kMinRefineHalfWindow, kMaxFollowHalfWindow);
      if (!(p.x >= half + 2 && p.y >= half + 2 && p.x <= image.cols - half - 3 &&
            p.y <= image.rows - half - 3))
        continue;
      refined_.assign(1, p);
      cv::cornerSubPix(
          image, refined_, cv::Size(half, half), cv::Size(-1, -1),
          cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 0.001));
      const cv::Point2f c = refined_.front();
      if (cv::norm(c - p) > kFollowReach * square || !has_contrast(image, c, half))
        continue;
      charuco_corners_.push_back(c);
      charuco_ids_.push_back(int(i));
    }
    if (charuco_ids_.size() < kMinFollowed) {
      charuco_corners_.clear();
      charuco_ids_.clear();
      return;
    }
    following_ = true;
  }

  // Something to refine on around `c`: the window's pixels spread by at
  // least kFollowContrast (a board's dark and light squares, however
  // blurred; not the grey of a floor where the board no longer is, on which
  // cornerSubPix stays where it was put).
  static bool has_contrast(const cv::Mat &image, cv::Point2f c, int half) {
    const cv::Rect window(int(std::lround(c.x)) - half, int(std::lround(c.y)) - half, 2 * half + 1,
                          2 * half + 1);
    cv::Scalar mean, deviation;
    cv::meanStdDev(image(window & cv::Rect(0, 0, image.cols, image.rows)), mean, deviation);
    return deviation[0] >= kFollowContrast;
  }

  MarkerBoard board_;
  cv::Ptr<cv::aruco::Dictionary> dictionary_;
  cv::Ptr<cv::aruco::DetectorParameters> parameters_;
  cv::Ptr<cv::aruco::CharucoBoard> charuco_;
  glm::dmat3 to_world_{1.0}; // a field's points are the world's
  // Kept between pictures, so that their storage is reused.
  std::vector<std::vector<cv::Point2f>> corners_;
  std::vector<int> ids_, charuco_ids_;
  std::vector<cv::Point2f> charuco_corners_, refined_, image_points_, projected_, predicted_;
  std::vector<cv::Point2f> read_corners_; // the corners read from the markers, while following
  std::vector<int> read_ids_;
  bool following_ = false; // this picture's corners were followed from the previous pose
  std::vector<cv::Point3f> object_;
  std::optional<BoardAligner> aligner_; // a ChArUco board's
  // light_table()s for full and limited range; the picture in light.
  const cv::Mat to_light_[2], to_light8_[2];
  cv::Mat light_;
};

// draw_board_page() (marker_tracker.h).
bool draw_page(const MarkerBoard &board, int pixels_per_square, BoardPage &out,
               std::string &error) {
  constexpr long kLargestSide = 16384;
  if (board.type != MarkerBoardType::charuco) {
    error = "a marker field has no page: its markers are printed one by one";
    return false;
  }
  const long width = long(board.squares_x) * pixels_per_square;
  const long height = long(board.squares_y) * pixels_per_square;
  if (pixels_per_square < 1 || width > kLargestSide || height > kLargestSide) {
    error = std::to_string(pixels_per_square) + " pixels a square make a page of " +
            std::to_string(width) + "x" + std::to_string(height) + "; at most " +
            std::to_string(kLargestSide) + " a side, at least 1 a square";
    return false;
  }
  const auto charuco = cv::aruco::CharucoBoard::create(
      board.squares_x, board.squares_y, float(board.square_m), float(board.marker_m),
      cv::aruco::getPredefinedDictionary(board.dictionary));
  cv::Mat page;
  charuco->draw(cv::Size(int(width), int(height)), page, 0, 1);
  out.width = page.cols;
  out.height = page.rows;
  out.grey.assign(page.datastart, page.dataend);
  return true;
}

class OpenCvModule final : public marker_module::Module {
public:
  std::unique_ptr<MarkerTracker> open(const MarkerBoard &board, std::string &error) override {
    try {
      return std::make_unique<OpenCvTracker>(board);
    } catch (const std::exception &e) {
      error = std::string("OpenCV: ") + e.what();
      return nullptr;
    }
  }

  bool calibrate(const MarkerBoard &board, const std::vector<LumaImage> &views,
                 CameraCalibration &out, std::string &error) override {
    try {
      return calibrate_views(board, views, out, error);
    } catch (const std::exception &e) {
      error = std::string("OpenCV: ") + e.what();
      return false;
    }
  }

  bool draw(const MarkerBoard &board, int pixels_per_square, BoardPage &out,
            std::string &error) override {
    try {
      return draw_page(board, pixels_per_square, out, error);
    } catch (const std::exception &e) {
      error = std::string("OpenCV: ") + e.what();
      return false;
    }
  }
};

} // namespace
} // namespace camhead::pipeline

extern "C" __attribute__((visibility("default"))) camhead::pipeline::marker_module::Module *
camhead_markers_module(int abi_version) {
  static camhead::pipeline::OpenCvModule module;
  return abi_version == camhead::pipeline::marker_module::kAbiVersion ? &module : nullptr;
}
