// The whole ChArUco board aligned with a picture too blurred to read it
// (the marker module's last way to a pose, marker_module.cpp): the board is
// drawn as a pose and the lens's defocus show it, and the drawing aligned
// with the picture. Inside libcamhead_markers.so only.
#pragma once

#include <cstddef>
#include <vector>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/core.hpp>

#include "../marker_tracker.h"

namespace camhead::pipeline {

// A ChArUco board's chessboard corners run row by row, `cols`
// (squares_x - 1) to a row, `n` in all. The corner next to corner `i`, whose
// distance is the square's size there: in its row where it has one, else in
// its column.
[[nodiscard]] std::size_t corner_neighbour(std::size_t i, std::size_t cols, std::size_t n);
// The corner above or below corner `i` (beside it on a board of one row).
[[nodiscard]] std::size_t column_neighbour(std::size_t i, std::size_t cols, std::size_t n);

class BoardAligner {
public:
  // Draws `charuco`'s page once, at 128 pixels a square and halved from
  // there down to 4.
  BoardAligner(const MarkerBoard &board, cv::Ptr<cv::aruco::CharucoBoard> charuco);

  // The blur of the board where (rvec, tvec) put it in a picture of
  // `picture` pixels: the median of its corners' in the picture (0 where
  // `camera`'s defocus is not known, NaN where too few corners are in the
  // picture).
  [[nodiscard]] double board_blur(const CameraModel &camera, const cv::Matx33d &k,
                                  const cv::Mat &distortion, const cv::Vec3d &rvec,
                                  const cv::Vec3d &tvec, cv::Size picture);

  // The board aligned with `image` (its codes, and `to_light`, the table
  // of 256 floats that decodes them to light), starting from (rvec, tvec)
  // and blurred by `blur` pixels: the chessboard corners and where the
  // alignment puts them in the picture, for the pose solve; false where it
  // does not align (align_board's checks).
  bool align(const cv::Mat &image, const cv::Mat &to_light, const cv::Matx33d &k,
             const cv::Mat &distortion, cv::Vec3d rvec, cv::Vec3d tvec, double blur,
             std::vector<cv::Point3f> &object, std::vector<cv::Point2f> &image_points);

private:
  bool align_once(const cv::Mat &image, const cv::Mat &to_light, const cv::Matx33d &k,
                  const cv::Mat &distortion, const cv::Vec3d &rvec, const cv::Vec3d &tvec,
                  double blur, bool first, bool &coarser, std::vector<cv::Point3f> &object,
                  std::vector<cv::Point2f> &image_points);
  // The light across the board, fitted to the picture once aligned: a gain
  // that changes linearly over the picture (a lamp nearer one side).
  void fit_shading(const cv::Matx33d &warp, const cv::Rect &roi, double scale);
  [[nodiscard]] bool in_picture(cv::Point2f p) const;
  [[nodiscard]] std::size_t neighbour(std::size_t i) const;
  [[nodiscard]] std::size_t column_neighbour(std::size_t i) const;

  MarkerBoard board_;
  cv::Ptr<cv::aruco::CharucoBoard> charuco_;
  // The page at 128 pixels a square, then halved; and the pictures and
  // maps of one alignment, kept so that their storage is reused.
  std::vector<cv::Mat> pages_;
  std::vector<double> blurs_;
  cv::Size picture_size_;
  std::vector<cv::Point3f> outline_;
  std::vector<cv::Point2f> predicted_, outline_image_, grid_, rays_, row_rays_;
  std::vector<int> column_ray_;
  std::vector<float> column_on_;
  // The drawing reaches past the picture's edges (drawn_whole_,
  // mask_whole_); drawn_ and mask_ are the picture's part of it.
  cv::Mat light_, picture_, drawn_sampled_, drawn_fine_, drawn_whole_, drawn_, map_x_, map_y_,
      mask_sampled_, mask_fine_, mask_whole_, mask_, warped_, warped_mask_;
  // The gain's slope across the picture, per picture width, in x and in y
  // (relative to the gain at the picture's centre): fitted by one pass,
  // drawn in by the next.
  cv::Vec2d shading_{0.0, 0.0};
};

} // namespace camhead::pipeline
