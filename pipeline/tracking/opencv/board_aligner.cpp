#include "board_aligner.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace camhead::pipeline {
namespace {

// From this much blur on (below it, reading or following its corners is
// as near the truth: marker_module.cpp), on a picture reduced by 2 or 4,
// whichever leaves the board's blur 2-4 pixels across (by 8 the board was
// 300 pixels and the pose walked: bench/RESULTS.md, "Registration through
// defocus"); kept if its drawing and the picture correlate this well
// (ECC's coefficient, 1 for a perfect match up to the light's gain and
// offset; 0.96-0.99 on the rig and the synthetic board), and if no corner
// moved by more than this fraction of a square from where the previous pose
// put it (a chessboard looks alike one square over: no slipping into that),
// and if at least as many corners as a followed board needs are in the
// picture. Two passes, the second from the first's pose.
constexpr int kMaxAlignLevel = 2;
constexpr double kMinAlignCorrelation = 0.8;
constexpr double kAlignReach = 0.4;
constexpr int kAlignPasses = 2;
constexpr std::size_t kMinCorners = 10;
// The board's outline is projected at this many points an edge (a
// distorting lens bends it); at least this many pixels of the reduced
// picture must be compared, and at most this many are (ECC's time grows
// with them). Rays through the lens are undistorted at every kRayStep-th
// pixel of the drawing's grid.
constexpr int kOutlineSteps = 8;
constexpr int kMinAlignPixels = 200, kMaxAlignPixels = 8000;
constexpr int kRayStep = 8;
// The board's page, drawn once, halved down to 4 pixels a square: the
// drawing samples the level with a square's size in the reduced picture.
constexpr int kPagePixelsPerSquare = 128, kSmallestPagePixelsPerSquare = 4;

// A defocused lens's blur, a uniform disc `diameter` pixels across with its
// edge antialiased (4x4 samples a pixel), summing to 1.
cv::Mat disc(double diameter) {
  const int r = int(std::ceil(diameter / 2.0));
  cv::Mat k(2 * r + 1, 2 * r + 1, CV_32F);
  for (int y = -r; y <= r; ++y)
    for (int x = -r; x <= r; ++x) {
      int inside = 0;
      for (int sy = 0; sy < 4; ++sy)
        for (int sx = 0; sx < 4; ++sx) {
          const double px = x + (sx + 0.5) / 4.0 - 0.5, py = y + (sy + 0.5) / 4.0 - 0.5;
          inside += px * px + py * py <= diameter * diameter / 4.0 ? 1 : 0;
        }
      k.at<float>(y + r, x + r) = float(inside);
    }
  return k / cv::sum(k)[0];
}

} // namespace

std::size_t corner_neighbour(std::size_t i, std::size_t cols, std::size_t n) {
  return i % cols + 1 < cols ? i + 1 : i % cols > 0 ? i - 1 : i + cols < n ? i + cols : i - cols;
}

std::size_t column_neighbour(std::size_t i, std::size_t cols, std::size_t n) {
  if (n <= cols)
    return corner_neighbour(i, cols, n);
  return i + cols < n ? i + cols : i - cols;
}

BoardAligner::BoardAligner(const MarkerBoard &board, cv::Ptr<cv::aruco::CharucoBoard> charuco)
    : board_(board), charuco_(std::move(charuco)) {
  cv::Mat page;
  charuco_->draw(
      cv::Size(board.squares_x * kPagePixelsPerSquare, board.squares_y * kPagePixelsPerSquare),
      page, 0, 1);
  pages_.emplace_back();
  page.convertTo(pages_.back(), CV_32F);
  for (int pps = kPagePixelsPerSquare / 2; pps >= kSmallestPagePixelsPerSquare; pps /= 2) {
    cv::Mat half;
    cv::resize(pages_.back(), half, cv::Size(board.squares_x * pps, board.squares_y * pps), 0, 0,
               cv::INTER_AREA);
    pages_.push_back(std::move(half));
  }
}

double BoardAligner::board_blur(const CameraModel &camera, const cv::Matx33d &k,
                                const cv::Mat &distortion, const cv::Vec3d &rvec,
                                const cv::Vec3d &tvec, cv::Size picture) {
  picture_size_ = picture;
  const std::vector<cv::Point3f> &corners = charuco_->chessboardCorners;
  cv::projectPoints(corners, rvec, tvec, k, distortion, predicted_);
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  blurs_.clear();
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const cv::Vec3d x = r * cv::Vec3d(corners[i].x, corners[i].y, corners[i].z) + tvec;
    if (x[2] > 0.0 && in_picture(predicted_[i]))
      blurs_.push_back(camera.defocus_px * std::abs(1.0 / camera.focus_m - 1.0 / x[2]));
  }
  if (blurs_.size() < kMinCorners)
    return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(blurs_.begin(), blurs_.begin() + long(blurs_.size() / 2), blurs_.end());
  return blurs_[blurs_.size() / 2];
}

// Where the board can be neither read nor followed (its markers and its
// corners lost in defocus: bench/RESULTS.md, "Registration through
// defocus"), it is drawn as the previous pose and the lens's defocus show
// it, and the
// drawing is aligned with the picture by a homography: OpenCV's ECC,
// which is blind to the light's gain and offset, on the picture reduced
// so far that the blur leaves nothing finer. A planar board is one
// homography away from any other view of it through a pinhole; the
// lens's distortion bends that a little, which the second pass, drawn
// from the first pass's pose, takes out. The chessboard corners moved as
// the alignment moves the drawn ones are the points the pose is solved
// from (object, image_points).
bool BoardAligner::align(const cv::Mat &image, const cv::Matx33d &k, const cv::Mat &distortion,
                         cv::Vec3d rvec, cv::Vec3d tvec, double blur,
                         std::vector<cv::Point3f> &object, std::vector<cv::Point2f> &image_points) {
  if (!std::isfinite(blur))
    return false; // too little of the board in the picture
  picture_size_ = image.size();
  for (int pass = 0; pass < kAlignPasses; ++pass) {
    if (!align_once(image, k, distortion, rvec, tvec, blur, object, image_points))
      return false;
    if (pass + 1 < kAlignPasses && !cv::solvePnP(object, image_points, k, distortion, rvec, tvec,
                                                 true, cv::SOLVEPNP_ITERATIVE))
      return false;
  }
  return true;
}

// One pass: the board drawn from (rvec, tvec) and aligned; the corners
// it moves into object and image_points.
bool BoardAligner::align_once(const cv::Mat &image, const cv::Matx33d &k, const cv::Mat &distortion,
                              const cv::Vec3d &rvec, const cv::Vec3d &tvec, double blur,
                              std::vector<cv::Point3f> &object,
                              std::vector<cv::Point2f> &image_points) {
  const std::vector<cv::Point3f> &corners = charuco_->chessboardCorners;
  cv::projectPoints(corners, rvec, tvec, k, distortion, predicted_);
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);

  // The picture reduced by 2^level, which leaves the blur 2-4 pixels (or
  // less, where the board would cover more than kMaxAlignPixels: ECC's
  // time grows with them), around the board: its outline where the pose
  // puts it (the lens bends its edges), widened by the blur.
  outline_.clear();
  const float width_m = float(board_.squares_x * board_.square_m),
              height_m = float(board_.squares_y * board_.square_m);
  for (int t = 0; t <= kOutlineSteps; ++t) {
    const float f = float(t) / kOutlineSteps;
    outline_.insert(outline_.end(), {{f * width_m, 0.0f, 0.0f},
                                     {f * width_m, height_m, 0.0f},
                                     {0.0f, f * height_m, 0.0f},
                                     {width_m, f * height_m, 0.0f}});
  }
  cv::projectPoints(outline_, rvec, tvec, k, distortion, outline_image_);
  const cv::Rect outline = cv::boundingRect(outline_image_) & cv::Rect({0, 0}, image.size());
  int level = std::max(1, int(std::floor(std::log2(std::max(blur, 1.0) / 2.0))));
  while (level < kMaxAlignLevel && (outline.area() >> (2 * level)) > kMaxAlignPixels)
    ++level;
  level = std::min(level, kMaxAlignLevel);
  const double scale = std::ldexp(1.0, -level);
  const cv::Size size(image.cols >> level, image.rows >> level);
  const int reach = int(std::ceil(blur * scale)) + 2;
  const cv::Rect roi = cv::Rect(int(std::floor(outline.x * scale)) - reach,
                                int(std::floor(outline.y * scale)) - reach,
                                int(std::ceil(outline.width * scale)) + 2 * reach,
                                int(std::ceil(outline.height * scale)) + 2 * reach) &
                       cv::Rect(cv::Point(0, 0), size);
  if (roi.width < 8 || roi.height < 8)
    return false;
  cv::resize(image, reduced_, size, 0, 0, cv::INTER_AREA);
  reduced_(roi).convertTo(picture_, CV_32F);

  // The board drawn as the camera saw it: each pixel of a grid twice as
  // fine as the reduced picture's sees the board's plane through the
  // lens (and reads the page level whose squares are no larger than
  // they are here), blurred as the lens blurs it, then reduced as the
  // picture was. The pixels the floor around the board blurs into are
  // left out of the comparison.
  const std::size_t middle = predicted_.size() / 2;
  const cv::Point2f m = predicted_[middle];
  const double square_fine = 2.0 * scale *
                             std::min(cv::norm(predicted_[neighbour(middle)] - m),
                                      cv::norm(predicted_[column_neighbour(middle)] - m));
  if (!(square_fine > 0.0 && std::isfinite(square_fine)))
    return false; // a pose that puts the board nowhere
  std::size_t page = 0;
  double pps = kPagePixelsPerSquare;
  while (page + 1 < pages_.size() && pps / 2.0 >= square_fine) {
    ++page;
    pps /= 2.0;
  }
  const cv::Size fine(2 * roi.width, 2 * roi.height);
  // The rays through the lens at every kRayStep-th pixel of the grid
  // (undistorting is iterative), bilinear between: the lens bends them
  // far too gently for that to show.
  const int columns = (fine.width - 1 + kRayStep - 1) / kRayStep + 1,
            rows = (fine.height - 1 + kRayStep - 1) / kRayStep + 1;
  grid_.resize(std::size_t(columns * rows));
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < columns; ++x)
      grid_[std::size_t(y * columns + x)] =
          cv::Point2f(float((roi.x + (x * kRayStep + 0.5) / 2.0) / scale - 0.5),
                      float((roi.y + (y * kRayStep + 0.5) / 2.0) / scale - 0.5));
  cv::undistortPoints(grid_, rays_, k, distortion);
  map_x_.create(fine, CV_32F);
  map_y_.create(fine, CV_32F);
  mask_fine_.create(fine, CV_8U);
  const cv::Vec3d normal(r(0, 2), r(1, 2), r(2, 2)); // the board's z in the camera
  const double plane = normal.dot(tvec);
  const cv::Matx33d rt = r.t();
  for (int y = 0; y < fine.height; ++y) {
    const int y0 = std::min(y / kRayStep, rows - 2);
    const float fy = float(y - y0 * kRayStep) / kRayStep;
    for (int x = 0; x < fine.width; ++x) {
      const int x0 = std::min(x / kRayStep, columns - 2);
      const float fx = float(x - x0 * kRayStep) / kRayStep;
      const cv::Point2f *at = &rays_[std::size_t(y0 * columns + x0)];
      const cv::Point2f ray = (1.0f - fy) * ((1.0f - fx) * at[0] + fx * at[1]) +
                              fy * ((1.0f - fx) * at[columns] + fx * at[columns + 1]);
      const cv::Vec3d d(ray.x, ray.y, 1.0);
      const double along = plane / normal.dot(d);
      const cv::Vec3d on = rt * (along * d - tvec); // on the board, metres
      const bool board =
          along > 0.0 && on[0] >= 0.0 && on[1] >= 0.0 && on[0] <= width_m && on[1] <= height_m;
      map_x_.at<float>(y, x) = board ? float(on[0] / board_.square_m * pps - 0.5) : -1.0f;
      map_y_.at<float>(y, x) = board ? float(on[1] / board_.square_m * pps - 0.5) : -1.0f;
      mask_fine_.at<std::uint8_t>(y, x) = board ? 255 : 0;
    }
  }
  cv::remap(pages_[page], drawn_fine_, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  const double blur_fine = 2.0 * blur * scale;
  if (blur_fine > 0.5)
    cv::filter2D(drawn_fine_, drawn_fine_, -1, disc(blur_fine), cv::Point(-1, -1), 0.0,
                 cv::BORDER_REPLICATE);
  cv::resize(drawn_fine_, drawn_, roi.size(), 0, 0, cv::INTER_AREA);
  cv::resize(mask_fine_, mask_, roi.size(), 0, 0, cv::INTER_AREA);
  cv::threshold(mask_, mask_, 254, 255, cv::THRESH_BINARY);
  const int margin = int(std::ceil(blur * scale / 2.0)) + 1;
  cv::erode(mask_, mask_,
            cv::getStructuringElement(cv::MORPH_RECT, {2 * margin + 1, 2 * margin + 1}));
  if (cv::countNonZero(mask_) < kMinAlignPixels)
    return false;

  // drawn(W(x)) ~ picture(x): W takes the picture to the drawing.
  // ECC throws where the two do not correlate at all (a picture without
  // the board): no alignment, and the markers are still looked for.
  cv::Mat warp = cv::Mat::eye(3, 3, CV_32F);
  double correlation = 0.0;
  try {
    correlation = cv::findTransformECC(
        picture_, drawn_, warp, cv::MOTION_HOMOGRAPHY,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30, 1e-4), mask_, 1);
  } catch (const cv::Exception &) {
    return false;
  }
  if (!(correlation >= kMinAlignCorrelation))
    return false;
  cv::Matx33d w;
  warp.convertTo(cv::Mat(w, false), CV_64F);
  const cv::Matx33d back = w.inv();

  // Each corner in the picture, moved as the alignment moves the drawing.
  const double square = square_fine / (2.0 * scale);
  object.clear();
  image_points.clear();
  for (std::size_t i = 0; i < corners.size(); ++i) {
    if (!in_picture(predicted_[i]))
      continue;
    const cv::Vec3d h = back * cv::Vec3d((predicted_[i].x + 0.5) * scale - 0.5 - roi.x,
                                         (predicted_[i].y + 0.5) * scale - 0.5 - roi.y, 1.0);
    const cv::Point2f moved(float((h[0] / h[2] + roi.x + 0.5) / scale - 0.5),
                            float((h[1] / h[2] + roi.y + 0.5) / scale - 0.5));
    if (!std::isfinite(moved.x) || !std::isfinite(moved.y) ||
        cv::norm(moved - predicted_[i]) > kAlignReach * square)
      return false; // moved too far: not this board, or a square over
    object.push_back(corners[i]);
    image_points.push_back(moved);
  }
  return object.size() >= kMinCorners;
}

bool BoardAligner::in_picture(cv::Point2f p) const {
  return p.x >= 0.0f && p.y >= 0.0f && p.x <= float(picture_size_.width - 1) &&
         p.y <= float(picture_size_.height - 1);
}

std::size_t BoardAligner::neighbour(std::size_t i) const {
  return corner_neighbour(i, std::size_t(board_.squares_x - 1), charuco_->chessboardCorners.size());
}

std::size_t BoardAligner::column_neighbour(std::size_t i) const {
  return pipeline::column_neighbour(i, std::size_t(board_.squares_x - 1),
                                    charuco_->chessboardCorners.size());
}

} // namespace camhead::pipeline
