// synthetic_view.h exposes its canvas a band of rows at a time; the picture
// must be exactly the one the whole canvas gives at once (the maps spread
// over it in one cv::resize, one remap, one area average).
#include <algorithm>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "synthetic_view.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

// The whole canvas seen through `camera`'s distortion at once.
cv::Mat distorted_whole(const cv::Mat &canvas, const CameraModel &camera, cv::Size size) {
  const double s = test::kSupersample, o = (s - 1.0) / 2.0;
  std::vector<cv::Point2d> pixels;
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u)
      pixels.emplace_back(u, v);
  const cv::Matx33d k(camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0);
  std::vector<cv::Point2d> preimage;
  cv::undistortPoints(pixels, preimage, k,
                      std::vector<double>(camera.distortion.begin(), camera.distortion.end()),
                      cv::noArray(), k,
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-14));
  cv::Mat map_x(size, CV_32F), map_y(size, CV_32F);
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u) {
      const cv::Point2d &p = preimage[std::size_t(v) * size.width + u];
      map_x.at<float>(v, u) = float(s * p.x + o);
      map_y.at<float>(v, u) = float(s * p.y + o);
    }
  cv::Mat big_x, big_y, seen;
  cv::resize(map_x, big_x, canvas.size(), 0.0, 0.0, cv::INTER_LINEAR);
  cv::resize(map_y, big_y, canvas.size(), 0.0, 0.0, cv::INTER_LINEAR);
  cv::remap(canvas, seen, big_x, big_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(128));
  return seen;
}

// The light of the whole canvas at once; the ideal pinhole's picture is the
// canvas itself.
cv::Mat exposed_whole(const cv::Mat &canvas, const CameraModel &camera, cv::Size size) {
  const bool ideal = std::all_of(camera.distortion.begin(), camera.distortion.end(),
                                 [](double k) { return k == 0.0; });
  const cv::Mat seen = ideal ? canvas : distorted_whole(canvas, camera, size);
  cv::Mat wide, light;
  seen.convertTo(wide, CV_32F, 190.0 / 255.0, 30.0);
  cv::resize(wide, light, size, 0.0, 0.0, cv::INTER_AREA);
  return light;
}

TEST(SyntheticView, TheBandsMakeTheWholeCanvasPicture) {
  // 150x90: bands of 16 rows and a last, short one.
  const cv::Size size(150, 90);
  CameraModel lens;
  lens.fx = 130.0;
  lens.fy = 131.0;
  lens.cx = 76.2;
  lens.cy = 43.9;
  lens.distortion = {-0.14, 0.05, 0.0009, -0.0006, 0.0};
  cv::Mat canvas(size.height * test::kSupersample, size.width * test::kSupersample, CV_8UC1);
  cv::RNG(3).fill(canvas, cv::RNG::UNIFORM, 0, 256);
  for (const CameraModel &camera : {lens, test::pinhole(size.width, size.height)}) {
    const cv::Mat whole = exposed_whole(canvas, camera, size);
    const cv::Mat banded = test::expose(canvas, camera, size);
    ASSERT_EQ(banded.size(), whole.size());
    EXPECT_EQ(cv::norm(banded, whole, cv::NORM_INF), 0.0)
        << (camera.distortion[0] != 0.0 ? "distorted" : "pinhole");
  }
}

} // namespace
} // namespace camhead::pipeline
