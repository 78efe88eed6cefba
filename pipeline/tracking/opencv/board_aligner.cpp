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
// picture. Two passes, the second from the first's pose (the first may
// run one reduction further: kMinCoarsePassPixels).
constexpr int kMaxAlignLevel = 2;
constexpr double kMinAlignCorrelation = 0.8;
constexpr double kAlignReach = 0.4;
constexpr int kAlignPasses = 2;
constexpr std::size_t kMinCorners = 10;
// ECC stops when an iteration raises the correlation by less than this
// (or after 30). At 1e-4 it ran on for iterations that moved no corner:
// the moving rig's loop tracked in 0.62-0.67 of the time at 1e-3, its
// registration the same within 0.03 px (bench/RESULTS.md, "ECC's
// stopping rule").
constexpr int kEccIterations = 30;
constexpr double kEccEpsilon = 1e-3;
// The board's outline is projected at this many points an edge (a
// distorting lens bends it); at least this many pixels of the reduced
// picture must be compared, and the reduction goes on (up to
// kMaxAlignLevel) while more than this many would be (ECC's time grows
// with them). Rays through the lens are undistorted at every kRayStep-th
// pixel of the drawing's grid.
constexpr int kOutlineSteps = 8;
constexpr int kMinAlignPixels = 200, kMaxAlignPixels = 8000;
// The first of the two passes runs one reduction further than the second
// where the board's outline (its bounding box in the picture) covers at
// least this many pixels there: on a quarter of the pixels. The moving
// rig's aligned frames tracked in two thirds of the time (at 1920x1080 the
// median and p90, at 720x576 the p90) and registered as well (frame by
// frame, the mean difference under 0.01 px; on two clean synthetic views
// the camera's position came out 0.1-0.6 mm further off); with no such
// floor the synthetic boards of tests/markers, a few hundred pixels there,
// were not aligned. Where that pass fails all the same (a board seen edge
// on, its eroded mask too small there), it runs again at the second's
// reduction (bench/RESULTS.md, "A coarser first pass").
constexpr int kMinCoarsePassPixels = 2000;
constexpr int kRayStep = 8;
// The drawing is blurred on its grid twice as fine as the reduced picture,
// then reduced; where the blur spans this many reduced pixels or more, it
// is reduced first and blurred there, with a disc a quarter the area on a
// quarter of the pixels. On the moving rig at 1920x1080 (32 px of blur and
// more at the reduction by 4) that took the aligned frames' p90 from 25 to
// 19 ms, and they registered as well (all within 1 px, the worst 0.87 ->
// 0.90 px: bench/RESULTS.md, "Aligned frames at 1920x1080: the blur on the
// reduced drawing"). From 4 reduced pixels on, a sharp synthetic board lit
// by a lamp through 19 px of blur aligned twice as far off at one view
// (0.13 -> 0.26 px: "Aligned frames at 1920x1080, against 12 ms").
constexpr double kBlurAfterReduction = 8.0;
// At most this many samples a grid pixel along one axis: for a board
// foreshortened 4 times or more (seen from 15 degrees above its plane).
constexpr int kMaxSamples = 4;
// The board's page, drawn once, halved down to 4 pixels a square: the
// drawing reads the level that its samples do not alias.
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

// Where pixel (x, y) of a picture reduced by `scale`, cut to `roi`, is in the
// whole picture of `size`: -0.5 to 0.5 from its centre, in picture widths
// (so a gain's slope does not depend on the reduction).
cv::Point2d across(const cv::Rect &roi, double scale, int x, int y, cv::Size size) {
  return {((roi.x + x + 0.5) / scale - 0.5 * size.width) / size.width,
          ((roi.y + y + 0.5) / scale - 0.5 * size.height) / size.width};
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
// it, and the drawing is aligned with the picture by a homography: OpenCV's
// ECC, which is blind to the light's gain and offset, on the picture
// reduced so far that the blur leaves nothing finer. A planar board is one
// homography away from any other view of it through a pinhole; the lens's
// distortion bends that a little, and a lamp lights one side brighter,
// which the second pass, drawn from the first pass's pose with the gain
// the first pass fitted, takes out. The chessboard corners moved as the
// alignment moves the drawn ones are the points the pose is solved from
// (object, image_points).
bool BoardAligner::align(const cv::Mat &image, const cv::Mat &to_light, const cv::Matx33d &k,
                         const cv::Mat &distortion, cv::Vec3d rvec, cv::Vec3d tvec, double blur,
                         std::vector<cv::Point3f> &object, std::vector<cv::Point2f> &image_points) {
  if (!std::isfinite(blur))
    return false; // too little of the board in the picture
  picture_size_ = image.size();
  shading_ = {0.0, 0.0};
  for (int pass = 0; pass < kAlignPasses; ++pass) {
    const bool last = pass + 1 == kAlignPasses;
    bool coarser = pass == 0;
    bool aligned = align_once(image, to_light, k, distortion, rvec, tvec, blur, pass == 0, coarser,
                              object, image_points);
    if (!aligned && coarser) { // the coarser first pass failed: again at the second's reduction
      coarser = false;
      aligned = align_once(image, to_light, k, distortion, rvec, tvec, blur, pass == 0, coarser,
                           object, image_points);
    }
    if (!aligned)
      return false;
    if (!last && !cv::solvePnP(object, image_points, k, distortion, rvec, tvec, true,
                               cv::SOLVEPNP_ITERATIVE))
      return false;
  }
  return true;
}

// One pass: the board drawn from (rvec, tvec) and aligned; the corners
// it moves into object and image_points. The `first` pass also fits the
// light's gain across the picture for the next pass to draw. `coarser`:
// one reduction further where the board allows it (kMinCoarsePassPixels);
// false on return where it did not.
bool BoardAligner::align_once(const cv::Mat &image, const cv::Mat &to_light, const cv::Matx33d &k,
                              const cv::Mat &distortion, const cv::Vec3d &rvec,
                              const cv::Vec3d &tvec, double blur, bool first, bool &coarser,
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
  // The first pass only brings the drawing near the picture for the
  // second, whose pose is the one kept: where the board's outline still
  // covers kMinCoarsePassPixels one reduction further, it may run there.
  coarser = coarser && (outline.area() >> (2 * (level + 1))) >= kMinCoarsePassPixels;
  if (coarser)
    ++level;
  const double scale = std::ldexp(1.0, -level);
  const cv::Size size(image.cols >> level, image.rows >> level);
  const int reach = int(std::ceil(blur * scale)) + 2;
  const cv::Rect around(int(std::floor(outline.x * scale)) - reach,
                        int(std::floor(outline.y * scale)) - reach,
                        int(std::ceil(outline.width * scale)) + 2 * reach,
                        int(std::ceil(outline.height * scale)) + 2 * reach);
  const cv::Rect roi = around & cv::Rect(cv::Point(0, 0), size);
  if (roi.width < 8 || roi.height < 8)
    return false;
  // The blur disc's radius and a pixel, in the reduced picture. The lens
  // brings light into the picture from up to that far past its edges: the
  // board is drawn that far past them too, and only then cut to the
  // picture. Drawn only up to the edge, the drawing's blur repeated its
  // last row past it, and the pixels along the edge were compared all the
  // same: the moving rig at 1920x1080, its board cut by the bottom edge,
  // registered 4.89 px off at the median through 55-70 px of blur, and
  // 0.66 px drawn past the edge (bench/RESULTS.md, "The board past the
  // picture's edge").
  const int radius = int(std::ceil(blur * scale / 2.0)) + 1;
  const cv::Rect drawing =
      around & cv::Rect(-radius, -radius, size.width + 2 * radius, size.height + 2 * radius);
  const cv::Rect in_drawing(roi.tl() - drawing.tl(), roi.size());
  // In light, not in the picture's code values: the lens blurs light and
  // the camera encodes it, so a blurred edge's code values are no blur of
  // the page's. Compared as coded, the moving rig's board through 20 px of
  // blur and more (its pictures at 16 rays a pixel, bench/rig_tracking)
  // registered 1.05 px off at the median, 1.39 px at worst; in light, 0.18
  // and 0.33 px (bench/RESULTS.md, "Late frames and the first"). Decoded
  // at full resolution, then averaged: averaging code values darkens.
  const cv::Rect full(roi.x << level, roi.y << level, roi.width << level, roi.height << level);
  cv::LUT(image(full), to_light, light_);
  cv::resize(light_, picture_, roi.size(), 0, 0, cv::INTER_AREA);

  // The board drawn as the camera saw it: each pixel of a grid twice as
  // fine as the reduced picture's sees the board's plane through the lens,
  // blurred as the lens blurs it, then reduced as the picture was. The
  // pixels the floor around the board blurs into are left out of the
  // comparison.
  //
  // A board seen at a slant has its squares foreshortened one way: n times
  // shorter than the other. The grid is sampled n times a pixel along the
  // picture's axis nearer that way, and the samples averaged, and the page
  // is read at the level whose squares have no more pixels than the
  // samples have across a square that way. A page read more coarsely than
  // its pixels aliases: its moire pulled the board's corners 0.35-0.96 px
  // off at a 37-degree view through 6-16 px of blur (bench/RESULTS.md,
  // "Registration through defocus: the page aliased, a lamp").
  const std::size_t middle = predicted_.size() / 2;
  const cv::Point2f m = predicted_[middle];
  const cv::Point2f along_row = predicted_[neighbour(middle)] - m,
                    along_column = predicted_[column_neighbour(middle)] - m;
  const cv::Point2f shorter =
      cv::norm(along_row) < cv::norm(along_column) ? along_row : along_column;
  const double square_fine = 2.0 * scale * cv::norm(shorter),
               square_fine_long =
                   2.0 * scale * std::max(cv::norm(along_row), cv::norm(along_column));
  if (!(square_fine > 0.0 && std::isfinite(square_fine_long)))
    return false; // a pose that puts the board nowhere
  const int n = std::clamp(int(std::ceil(square_fine_long / square_fine - 1e-3)), 1, kMaxSamples);
  const bool upright = std::abs(shorter.y) >= std::abs(shorter.x);
  const int nx = upright ? 1 : n, ny = upright ? n : 1;
  std::size_t page = 0;
  double pps = kPagePixelsPerSquare;
  while (page + 1 < pages_.size() && pps > n * square_fine) {
    ++page;
    pps /= 2.0;
  }
  const cv::Size fine(2 * drawing.width, 2 * drawing.height),
      sampled(nx * fine.width, ny * fine.height);
  // The rays through the lens at every kRayStep-th pixel of the grid
  // (undistorting is iterative), bilinear between (the lens bends them far
  // too gently for that to show), each followed to the board's plane.
  // Interpolating where they meet the plane instead moved the drawing 0.1 px
  // at a 21-degree view: the perspective bends that.
  const int columns = (fine.width - 1 + kRayStep - 1) / kRayStep + 1,
            rows = (fine.height - 1 + kRayStep - 1) / kRayStep + 1;
  grid_.resize(std::size_t(columns * rows));
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < columns; ++x)
      grid_[std::size_t(y * columns + x)] =
          cv::Point2f(float((drawing.x + (x * kRayStep + 0.5) / 2.0) / scale - 0.5),
                      float((drawing.y + (y * kRayStep + 0.5) / 2.0) / scale - 0.5));
  cv::undistortPoints(grid_, rays_, k, distortion);
  // The board's plane in the camera: its normal (the board's z) and its
  // distance; a point of the plane back to the board's axes by r^T.
  const float n0 = float(r(0, 2)), n1 = float(r(1, 2)), n2 = float(r(2, 2));
  const float plane = float(cv::Vec3d(r(0, 2), r(1, 2), r(2, 2)).dot(tvec));
  const cv::Matx33f rt = cv::Matx33f(r.t());
  const float t0 = float(tvec[0]), t1 = float(tvec[1]), t2 = float(tvec[2]);
  map_x_.create(sampled, CV_32F);
  map_y_.create(sampled, CV_32F);
  mask_sampled_.create(sampled, CV_8U);
  // Where sample i, `per` to a grid pixel, lies between the rays: the ray
  // before it and how far on to the next.
  const auto between = [](int i, int per, int nodes, int &before, float &on) {
    const float g = (float(i) + 0.5f) / float(per) - 0.5f; // in grid pixels
    before = std::clamp(int(std::floor(g / kRayStep)), 0, nodes - 2);
    on = (g - float(before * kRayStep)) / kRayStep;
  };
  column_ray_.resize(std::size_t(sampled.width));
  column_on_.resize(std::size_t(sampled.width));
  for (int x = 0; x < sampled.width; ++x)
    between(x, nx, columns, column_ray_[std::size_t(x)], column_on_[std::size_t(x)]);
  row_rays_.resize(std::size_t(columns));
  const float to_page = float(pps / board_.square_m);
  for (int y = 0; y < sampled.height; ++y) {
    int y0 = 0;
    float fy = 0.0f;
    between(y, ny, rows, y0, fy);
    for (int c = 0; c < columns; ++c)
      row_rays_[std::size_t(c)] = (1.0f - fy) * rays_[std::size_t(y0 * columns + c)] +
                                  fy * rays_[std::size_t((y0 + 1) * columns + c)];
    float *map_x = map_x_.ptr<float>(y), *map_y = map_y_.ptr<float>(y);
    std::uint8_t *inside = mask_sampled_.ptr<std::uint8_t>(y);
    for (int x = 0; x < sampled.width; ++x) {
      const std::size_t x0 = std::size_t(column_ray_[std::size_t(x)]);
      const float fx = column_on_[std::size_t(x)];
      const cv::Point2f ray = (1.0f - fx) * row_rays_[x0] + fx * row_rays_[x0 + 1];
      // Along the ray (ray.x, ray.y, 1) to the plane, then into the board's
      // axes: metres on the board.
      const float along = plane / (n0 * ray.x + n1 * ray.y + n2);
      const float p0 = along * ray.x - t0, p1 = along * ray.y - t1, p2 = along - t2;
      const float u = rt(0, 0) * p0 + rt(0, 1) * p1 + rt(0, 2) * p2,
                  v = rt(1, 0) * p0 + rt(1, 1) * p1 + rt(1, 2) * p2;
      const bool board = along > 0.0f && u >= 0.0f && v >= 0.0f && u <= width_m && v <= height_m;
      map_x[x] = board ? u * to_page - 0.5f : -1.0f;
      map_y[x] = board ? v * to_page - 0.5f : -1.0f;
      inside[x] = board ? 255 : 0;
    }
  }
  if (n == 1) {
    cv::remap(pages_[page], drawn_fine_, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    mask_sampled_.copyTo(mask_fine_);
  } else {
    cv::remap(pages_[page], drawn_sampled_, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    cv::resize(drawn_sampled_, drawn_fine_, fine, 0, 0, cv::INTER_AREA);
    cv::resize(mask_sampled_, mask_fine_, fine, 0, 0, cv::INTER_AREA);
    cv::threshold(mask_fine_, mask_fine_, 254, 255, cv::THRESH_BINARY);
  }
  // The lens's blur, on the fine grid; where it spans kBlurAfterReduction
  // pixels of the reduced picture or more, on the drawing reduced.
  const double blur_reduced = blur * scale;
  const bool blur_after = blur_reduced >= kBlurAfterReduction;
  if (!blur_after && 2.0 * blur_reduced > 0.5)
    cv::filter2D(drawn_fine_, drawn_fine_, -1, disc(2.0 * blur_reduced), cv::Point(-1, -1), 0.0,
                 cv::BORDER_REPLICATE);
  cv::resize(drawn_fine_, drawn_whole_, drawing.size(), 0, 0, cv::INTER_AREA);
  if (blur_after)
    cv::filter2D(drawn_whole_, drawn_whole_, -1, disc(blur_reduced), cv::Point(-1, -1), 0.0,
                 cv::BORDER_REPLICATE);
  drawn_ = drawn_whole_(in_drawing);
  // The lamp's gain the pass before fitted (fit_shading keeps it between
  // 1/5 and 9/5 over the board).
  if (shading_ != cv::Vec2d(0.0, 0.0))
    for (int y = 0; y < drawn_.rows; ++y)
      for (int x = 0; x < drawn_.cols; ++x) {
        const cv::Point2d u = across(roi, scale, x, y, image.size());
        drawn_.at<float>(y, x) *= float(1.0 + shading_[0] * u.x + shading_[1] * u.y);
      }
  // The board's pixels the floor around it does not blur into.
  cv::resize(mask_fine_, mask_whole_, drawing.size(), 0, 0, cv::INTER_AREA);
  cv::threshold(mask_whole_, mask_whole_, 254, 255, cv::THRESH_BINARY);
  cv::erode(mask_whole_, mask_whole_,
            cv::getStructuringElement(cv::MORPH_RECT, {2 * radius + 1, 2 * radius + 1}));
  mask_ = mask_whole_(in_drawing);
  if (cv::countNonZero(mask_) < kMinAlignPixels)
    return false;

  // drawn(W(x)) ~ picture(x): W takes the picture to the drawing.
  // ECC throws where the two do not correlate at all (a picture without
  // the board): no alignment, and the markers are still looked for.
  cv::Mat warp = cv::Mat::eye(3, 3, CV_32F);
  double correlation = 0.0;
  try {
    correlation =
        cv::findTransformECC(picture_, drawn_, warp, cv::MOTION_HOMOGRAPHY,
                             cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS,
                                              kEccIterations, kEccEpsilon),
                             mask_, 1);
  } catch (const cv::Exception &) {
    return false;
  }
  if (!(correlation >= kMinAlignCorrelation))
    return false;
  cv::Matx33d w;
  warp.convertTo(cv::Mat(w, false), CV_64F);
  const cv::Matx33d back = w.inv();
  if (first)
    fit_shading(w, roi, scale);

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

void BoardAligner::fit_shading(const cv::Matx33d &warp, const cv::Rect &roi, double scale) {
  // The drawing (and which of its pixels are the board's) as aligned, where
  // the picture is: picture ~ gain * drawn + offset, the gain linear across
  // the picture. Least squares over the board's pixels; the slopes relative
  // to the gain at the picture's centre.
  cv::warpPerspective(drawn_, warped_, cv::Mat(warp), picture_.size(),
                      cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
  cv::warpPerspective(mask_, warped_mask_, cv::Mat(warp), picture_.size(),
                      cv::INTER_NEAREST | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT);
  cv::Matx44d normal = cv::Matx44d::zeros();
  cv::Vec4d right(0.0, 0.0, 0.0, 0.0);
  for (int y = 0; y < picture_.rows; ++y)
    for (int x = 0; x < picture_.cols; ++x) {
      if (warped_mask_.at<std::uint8_t>(y, x) == 0)
        continue;
      const double d = warped_.at<float>(y, x);
      const cv::Point2d u = across(roi, scale, x, y, picture_size_);
      const cv::Vec4d row(d, d * u.x, d * u.y, 1.0);
      normal += row * row.t();
      right += double(picture_.at<float>(y, x)) * row;
    }
  cv::Vec4d g;
  if (!cv::solve(normal, right, g, cv::DECOMP_CHOLESKY) || !(g[0] > 0.0)) {
    shading_ = {0.0, 0.0};
    return;
  }
  // The drawing already carries the gain fitted before: what is left adds
  // to it (to first order). A gain that stays within 1/5 and 9/5 of its
  // value at the picture's centre over the board is light; anything steeper
  // is not a lamp (the board half hidden, say), and the board is drawn
  // evenly lit.
  shading_ += cv::Vec2d(g[1] / g[0], g[2] / g[0]);
  for (const cv::Point corner : {cv::Point(0, 0), cv::Point(roi.width, 0), cv::Point(0, roi.height),
                                 cv::Point(roi.width, roi.height)}) {
    const cv::Point2d u = across(roi, scale, corner.x, corner.y, picture_size_);
    if (std::abs(shading_[0] * u.x + shading_[1] * u.y) > 0.8)
      shading_ = {0.0, 0.0};
  }
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
