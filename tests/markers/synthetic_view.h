// Pictures of marker boards as a camera at a known pose sees them, made with
// OpenCV's own drawing of the board and a perspective warp, supersampled
// 8x8 (a sensor integrates over its pixels), on a grey floor, in video
// range, with the sensor's noise: the truth the marker tracker is measured
// against. Independent of camhead's renderer on purpose.
//
// The supersampling sets how finely an edge can sit: the warp samples the
// page at points, so a sharp edge lands on the supersampled grid, and 4x4
// moved the board's corners by up to 1/8 px with their phase in the pixel
// (seen: rows of corners off by +0.15 and -0.06 px). At 8x8 the page's own
// pixels (1/240 of a square) are wider than the samples, and the warp's
// linear interpolation makes every edge a ramp the box filter integrates.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>
#include <opencv2/aruco.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "tracking/marker_board.h"
#include "tracking/marker_tracker.h"

namespace camhead::pipeline::test {

// The board the marker tests and benchmarks track: a 9x6 ChArUco of 10 cm
// squares and 7.5 cm markers (5X5_100), about A1; on the floor, its centre
// at kFloorBoardCentre.
inline constexpr const char *kFloorBoardJson =
    R"({"format": "camhead-markers", "version": 1, "name": "floor", "type": "charuco",
        "dictionary": "5X5_100", "squares": [9, 6], "square_m": 0.1, "marker_m": 0.075})";
inline const glm::dvec3 kFloorBoardCentre(0.45, 0.0, 0.30);
inline MarkerBoard floor_board() {
  return parse_marker_board(kFloorBoardJson, "floor.json");
}

// A pinhole of `focal_mm` on a 36 mm wide sensor, centred, `width` x
// `height` pixels (35 mm at 720 wide: 700 px).
inline CameraModel pinhole(int width, int height, double focal_mm = 35.0) {
  CameraModel c;
  c.fx = c.fy = focal_mm / 36.0 * width;
  c.cx = (width - 1) / 2.0;
  c.cy = (height - 1) / 2.0;
  return c;
}

constexpr int kSupersample = 8;

// OpenCV's camera-from-world rotation and translation for a camhead pose.
inline void extrinsics(const CameraPose &pose, cv::Matx33d &r, cv::Vec3d &t) {
  const glm::dmat3 axes = glm::mat3_cast(pose.orientation); // columns: right, up, back
  const glm::dvec3 x = axes[0], y = -axes[1], z = -axes[2]; // OpenCV: right, down, ahead
  r = cv::Matx33d(x.x, x.y, x.z, y.x, y.y, y.z, z.x, z.y, z.z);
  const cv::Vec3d p(pose.position.x, pose.position.y, pose.position.z);
  t = -(r * p);
}

// The camera matrix of the supersampled picture whose pixel blocks average
// to the picture of `camera`.
inline cv::Matx33d supersampled(const CameraModel &camera) {
  const double s = kSupersample, o = (s - 1.0) / 2.0;
  return {s * camera.fx, 0.0, s * camera.cx + o, 0.0, s * camera.fy, s * camera.cy + o, 0.0,
          0.0,           1.0};
}

// One frame of that light as a camera codes it: Gaussian noise of `noise`
// (the sensor's, in the light's 0..255 units), then sRGB's curve (as
// camhead's renderer takes a camera's video to be coded), quantized to 8
// bits. The noise is OpenCV's generator, seeded from `random`: drawn pixel
// by pixel through <random>, it was half of the marker tests' time in the
// unoptimised sanitizer build.
inline cv::Mat frame(const cv::Mat &light, double noise, std::mt19937 &random) {
  CV_Assert(light.type() == CV_32F);
  cv::Mat v = light * (1.0 / 255.0); // `light` is every frame's and stays as it is
  if (noise > 0.0) {
    cv::Mat grain(light.size(), CV_32F);
    cv::RNG(random()).fill(grain, cv::RNG::NORMAL, 0.0, noise / 255.0);
    v += grain;
  }
  v = cv::max(cv::min(v, 1.0), 0.0);
  // sRGB's encoding (IEC 61966-2-1), whole-picture operations (OpenCV's,
  // fast in any build).
  cv::Mat code;
  cv::pow(v, 1.0 / 2.4, code);
  code = code * (1.055 * 255.0) - 0.055 * 255.0;
  const cv::Mat dark = v * (12.92 * 255.0);
  dark.copyTo(code, v <= 0.0031308);
  cv::Mat out;
  code.convertTo(out, CV_8U); // rounded and saturated, as a sensor's ADC
  return out;
}

// The light on the sensor at `size` (video-range luma, not yet quantized)
// from a supersampled `canvas` of 0..255 values (128 where nothing was
// drawn) made through the ideal pinhole of `camera`'s matrix, seen through
// its distortion: each pixel takes the ideal picture at its preimage
// (OpenCV's undistortPoints, converged), the map computed at the picture's
// pixels and spread over the canvas's linearly, and each pixel's block of
// the canvas averaged. Done a band of rows at a time, so that the canvas-
// sized maps and floats (hundreds of MB at 960x540) are never made whole.
inline cv::Mat expose(const cv::Mat &canvas, const CameraModel &camera, cv::Size size) {
  const bool ideal = std::all_of(camera.distortion.begin(), camera.distortion.end(),
                                 [](double k) { return k == 0.0; });
  const double s = kSupersample, o = (s - 1.0) / 2.0;
  // Where each picture pixel's centre comes from on the canvas.
  cv::Mat from_x(size, CV_32F), from_y(size, CV_32F);
  if (!ideal) {
    std::vector<cv::Point2d> pixels;
    for (int v = 0; v < size.height; ++v)
      for (int u = 0; u < size.width; ++u)
        pixels.emplace_back(u, v);
    const cv::Matx33d k(camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0);
    std::vector<cv::Point2d> preimage;
    cv::undistortPoints(
        pixels, preimage, k,
        std::vector<double>(camera.distortion.begin(), camera.distortion.end()), cv::noArray(), k,
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-14));
    for (int v = 0; v < size.height; ++v)
      for (int u = 0; u < size.width; ++u) {
        const cv::Point2d &p = preimage[std::size_t(v) * size.width + u];
        from_x.at<float>(v, u) = float(s * p.x + o);
        from_y.at<float>(v, u) = float(s * p.y + o);
      }
  }
  constexpr int kBandRows = 16; // picture rows per band
  cv::Mat light(size, CV_32F);
  cv::Mat map_x, map_y, seen, wide, small;
  for (int v0 = 0; v0 < size.height; v0 += kBandRows) {
    const int rows = std::min(kBandRows, size.height - v0);
    const cv::Range canvas_rows(v0 * kSupersample, (v0 + rows) * kSupersample);
    if (ideal) {
      seen = canvas.rowRange(canvas_rows);
    } else {
      // The maps spread over the band's canvas rows by cv::resize (OpenCV's,
      // fast in any build) of the picture rows around the band: the band's
      // rows are exactly those of the whole map spread at once, since each
      // takes the same two picture rows at the same weights.
      const int lo = std::max(v0 - 1, 0), hi = std::min(v0 + rows + 1, size.height);
      const cv::Size spread(canvas.cols, (hi - lo) * kSupersample);
      const cv::Range band((v0 - lo) * kSupersample, (v0 - lo + rows) * kSupersample);
      cv::resize(from_x.rowRange(lo, hi), map_x, spread, 0.0, 0.0, cv::INTER_LINEAR);
      cv::resize(from_y.rowRange(lo, hi), map_y, spread, 0.0, 0.0, cv::INTER_LINEAR);
      cv::remap(canvas, seen, map_x.rowRange(band), map_y.rowRange(band), cv::INTER_LINEAR,
                cv::BORDER_CONSTANT, cv::Scalar(128));
    }
    seen.convertTo(wide, CV_32F, 190.0 / 255.0, 30.0);
    cv::resize(wide, small, cv::Size(size.width, rows), 0.0, 0.0, cv::INTER_AREA);
    small.copyTo(light.rowRange(v0, v0 + rows));
  }
  return light;
}

// A ChArUco board where marker_board.h puts it, seen from `pose` through
// `camera` (its distortion too): the light.
inline cv::Mat charuco_view(const MarkerBoard &board, const CameraModel &camera,
                            const CameraPose &pose, cv::Size size) {
  const auto dictionary = cv::aruco::getPredefinedDictionary(board.dictionary);
  const auto charuco = cv::aruco::CharucoBoard::create(
      board.squares_x, board.squares_y, float(board.square_m), float(board.marker_m), dictionary);
  constexpr int kPixelsPerSquare = 240;
  cv::Mat page;
  charuco->draw(cv::Size(board.squares_x * kPixelsPerSquare, board.squares_y * kPixelsPerSquare),
                page, 0, 1);
  // The page's pixel (u, v), centres at integers, is board point
  // ((u + 0.5) a, (v + 0.5) a): its edges are the board's.
  const double a = board.square_m / kPixelsPerSquare;
  const cv::Matx33d page_to_board(a, 0.0, 0.5 * a, 0.0, a, 0.5 * a, 0.0, 0.0, 1.0);
  // Board point (x, y, 0) to world (marker_board.h), then to the camera.
  cv::Matx33d r;
  cv::Vec3d t;
  extrinsics(pose, r, t);
  const cv::Matx33d board_to_world(1, 0, 0, 0, 0, -1, 0, 1, 0);
  const cv::Matx33d rb = r * board_to_world;
  const cv::Matx33d plane(rb(0, 0), rb(0, 1), t[0], rb(1, 0), rb(1, 1), t[1], rb(2, 0), rb(2, 1),
                          t[2]);
  const cv::Matx33d h = supersampled(camera) * plane * page_to_board;
  cv::Mat canvas;
  cv::warpPerspective(page, canvas, cv::Mat(h),
                      cv::Size(size.width * kSupersample, size.height * kSupersample),
                      cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(128));
  return expose(canvas, camera, size);
}

// A marker field's markers, each with a white quiet zone of one cell around
// it, seen from `pose`: the light.
inline cv::Mat field_view(const MarkerBoard &board, const CameraModel &camera,
                          const CameraPose &pose, cv::Size size) {
  const auto dictionary = cv::aruco::getPredefinedDictionary(board.dictionary);
  const int cells = dictionary->markerSize + 2; // bits and the black border
  constexpr int kPixelsPerCell = 40;
  cv::Matx33d r;
  cv::Vec3d t;
  extrinsics(pose, r, t);
  const cv::Matx33d k = supersampled(camera);
  cv::Mat canvas(size.height * kSupersample, size.width * kSupersample, CV_8UC1, cv::Scalar(128));
  for (const PlacedMarker &m : board.markers) {
    cv::Mat marker;
    cv::aruco::drawMarker(dictionary, m.id, cells * kPixelsPerCell, marker, 1);
    cv::Mat padded;
    cv::copyMakeBorder(marker, padded, kPixelsPerCell, kPixelsPerCell, kPixelsPerCell,
                       kPixelsPerCell, cv::BORDER_CONSTANT, cv::Scalar(255));
    // The padded square's corners in the world: the marker's, moved out by
    // one cell of its side.
    const glm::dvec3 centre = (m.corners[0] + m.corners[2]) / 2.0;
    const double grow = double(cells + 2) / cells;
    std::vector<cv::Point3d> world;
    for (const glm::dvec3 &c : m.corners) {
      const glm::dvec3 p = centre + grow * (c - centre);
      world.emplace_back(p.x, p.y, p.z);
    }
    std::vector<cv::Point2d> projected;
    cv::Mat rvec;
    cv::Rodrigues(cv::Mat(r), rvec);
    cv::projectPoints(world, rvec, cv::Mat(t), cv::Mat(k), cv::Mat(), projected);
    const float e = float(padded.cols) - 0.5f, b = -0.5f; // the page's outer edges
    const cv::Point2f from[4] = {{b, b}, {e, b}, {e, e}, {b, e}};
    const cv::Point2f to[4] = {projected[0], projected[1], projected[2], projected[3]};
    const cv::Mat h = cv::getPerspectiveTransform(from, to);
    cv::Mat warped, mask;
    cv::warpPerspective(padded, warped, h, canvas.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                        cv::Scalar(0));
    cv::warpPerspective(cv::Mat(padded.size(), CV_8UC1, cv::Scalar(255)), mask, h, canvas.size(),
                        cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
    // Blend by coverage, so that the pasted square's edges are antialiased.
    for (int y = 0; y < canvas.rows; ++y)
      for (int x = 0; x < canvas.cols; ++x) {
        const int w = mask.at<std::uint8_t>(y, x);
        if (w > 0)
          canvas.at<std::uint8_t>(y, x) =
              std::uint8_t((warped.at<std::uint8_t>(y, x) * 255 +
                            canvas.at<std::uint8_t>(y, x) * (255 - w) + 127) /
                           255);
      }
  }
  // The field's pictures are the ideal pinhole's (its markers projected
  // without distortion).
  CameraModel pinhole = camera;
  std::fill(pinhole.distortion.begin(), pinhole.distortion.end(), 0.0);
  return expose(canvas, pinhole, size);
}

} // namespace camhead::pipeline::test
