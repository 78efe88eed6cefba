#include "camera_calibrator.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/aruco.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/core.hpp>

#include "code_to_light.h"

namespace camhead::pipeline {
namespace {

// calibrate_camera() (marker_tracker.h). The corners of each view are
// ChArUco's, interpolated from its markers and refined on the chessboard
// (OpenCV's interpolateCornersCharuco); the fit is calibrateCameraCharuco
// with OpenCV's five coefficients (k1 k2 p1 p2 k3).
class Calibrator {
public:
  // A view gives at least this many corners, and the fit this many views.
  static constexpr int kLeastCorners = 8;
  static constexpr int kLeastViews = 4;
  // A view whose error is over this many times the median (and over
  // kOutlierFloorPx) is left out and the fit repeated once.
  static constexpr double kOutlierRatio = 3.0;
  static constexpr double kOutlierFloorPx = 0.3;

  bool run(const MarkerBoard &board, const std::vector<LumaImage> &views, CameraCalibration &out,
           std::string &error) {
    if (board.type != MarkerBoardType::charuco) {
      error = "a camera is calibrated from a ChArUco board; this is a marker field";
      return false;
    }
    if (views.empty()) {
      error = "no views to calibrate from";
      return false;
    }
    const auto dictionary = cv::aruco::getPredefinedDictionary(board.dictionary);
    const auto charuco = cv::aruco::CharucoBoard::create(
        board.squares_x, board.squares_y, float(board.square_m), float(board.marker_m), dictionary);
    const auto parameters = cv::aruco::DetectorParameters::create();
    const cv::Mat to_light8[2] = {light_table(false, CV_8U), light_table(true, CV_8U)};
    const cv::Size size(views.front().width, views.front().height);
    out = {};
    out.views.resize(views.size());
    std::vector<cv::Mat> corners, ids;
    std::vector<std::size_t> view_of;
    for (std::size_t i = 0; i < views.size(); ++i) {
      const LumaImage &luma = views[i];
      CalibrationView &view = out.views[i];
      if (luma.width != size.width || luma.height != size.height) {
        view.why_not = "its size differs from the first view's";
        continue;
      }
      const cv::Mat codes(luma.height, luma.width, CV_8UC1, const_cast<std::uint8_t *>(luma.data),
                          std::size_t(luma.stride));
      cv::Mat image;
      cv::LUT(codes, to_light8[luma.limited_range ? 1 : 0], image);
      std::vector<std::vector<cv::Point2f>> marker_corners;
      std::vector<int> marker_ids;
      cv::aruco::detectMarkers(image, dictionary, marker_corners, marker_ids, parameters);
      cv::Mat view_corners, view_ids;
      if (!marker_ids.empty())
        cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, image, charuco,
                                             view_corners, view_ids);
      view.corners = view_corners.rows;
      if (view.corners < kLeastCorners) {
        view.why_not = std::to_string(marker_ids.size()) + " markers and " +
                       std::to_string(view.corners) + " corners found, " +
                       std::to_string(kLeastCorners) + " corners needed";
        continue;
      }
      corners.push_back(view_corners);
      ids.push_back(view_ids);
      view_of.push_back(i);
    }
    std::vector<double> errors;
    if (!fit(corners, ids, charuco, size, out, errors, error))
      return false;
    // Outliers: far above the median view, left out once.
    std::vector<double> sorted = errors;
    std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
    const double limit = std::max(kOutlierRatio * sorted[sorted.size() / 2], kOutlierFloorPx);
    std::vector<cv::Mat> kept_corners, kept_ids;
    std::vector<std::size_t> kept_of;
    for (std::size_t k = 0; k < errors.size(); ++k) {
      if (errors[k] > limit) {
        char why[128];
        std::snprintf(why, sizeof why, "its error, %.2f px, is over %.1f times the median view's",
                      errors[k], kOutlierRatio);
        out.views[view_of[k]].why_not = why;
        continue;
      }
      kept_corners.push_back(corners[k]);
      kept_ids.push_back(ids[k]);
      kept_of.push_back(view_of[k]);
    }
    if (kept_of.size() != view_of.size() &&
        !fit(kept_corners, kept_ids, charuco, size, out, errors, error))
      return false;
    for (std::size_t k = 0; k < kept_of.size(); ++k) {
      out.views[kept_of[k]].used = true;
      out.views[kept_of[k]].rms_px = errors[k];
    }
    return true;
  }

private:
  static bool fit(const std::vector<cv::Mat> &corners, const std::vector<cv::Mat> &ids,
                  const cv::Ptr<cv::aruco::CharucoBoard> &charuco, cv::Size size,
                  CameraCalibration &out, std::vector<double> &errors, std::string &error) {
    if (int(corners.size()) < kLeastViews) {
      error = std::to_string(corners.size()) + " views with the board usable, " +
              std::to_string(kLeastViews) + " needed";
      return false;
    }
    cv::Mat k, distortion, intrinsics_sd, extrinsics_sd, per_view;
    std::vector<cv::Mat> rvecs, tvecs;
    out.rms_px = cv::aruco::calibrateCameraCharuco(
        corners, ids, charuco, size, k, distortion, rvecs, tvecs, intrinsics_sd, extrinsics_sd,
        per_view, 0, cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
    out.camera.fx = k.at<double>(0, 0);
    out.camera.fy = k.at<double>(1, 1);
    out.camera.cx = k.at<double>(0, 2);
    out.camera.cy = k.at<double>(1, 2);
    for (int i = 0; i < 5; ++i)
      out.camera.distortion[std::size_t(i)] = distortion.at<double>(i);
    errors.assign(per_view.begin<double>(), per_view.end<double>());
    return true;
  }
};

} // namespace

bool calibrate_views(const MarkerBoard &board, const std::vector<LumaImage> &views,
                     CameraCalibration &out, std::string &error) {
  return Calibrator().run(board, views, out, error);
}

} // namespace camhead::pipeline
