// `camhead calibrate camera` (issue 25, test 4): the camera model of a
// simulated lens, fitted from pictures of a ChArUco board drawn through it,
// comes back (k1 within 2 %, RMS under 0.1 px); the command writes it into
// a lens profile that then gives it back; and a run that fails leaves the
// profile as it was.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "camhead/lens_control/lens_profile.h"
#include "camhead/renderer/image_io.h"
#include "synthetic_view.h"
#include "test_support.h"
#include "tracking/calibration_views.h"
#include "tracking/camera_pose.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 960, kHeight = 540;

// The simulated lens: a noticeable barrel, a little decentring, the
// principal point off centre (OpenCV's pixel centres).
CameraModel simulated_lens() {
  CameraModel c;
  c.fx = 820.0;
  c.fy = 822.5;
  c.cx = 485.3;
  c.cy = 262.1;
  c.distortion = {-0.14, 0.05, 0.0009, -0.0006, 0.0};
  return c;
}

// Views from around the board on the floor, 0.8-1.3 m away, tilted by
// 20-60 degrees from straight down, looking past its centre so that it
// lands in every part of the picture.
std::vector<cv::Mat> board_views(const CameraModel &lens, int count) {
  const MarkerBoard board = test::floor_board();
  std::mt19937 random(11);
  std::vector<cv::Mat> views;
  for (int k = 0; k < count; ++k) {
    const double azimuth = 2.0 * std::numbers::pi * k / count;
    const double tilt = (20.0 + 40.0 * ((k * 7) % count) / count) * std::numbers::pi / 180.0;
    const double distance = 0.8 + 0.5 * ((k * 3) % count) / count;
    const glm::dvec3 centre = test::kFloorBoardCentre;
    const glm::dvec3 from =
        centre + distance * glm::dvec3(std::sin(tilt) * std::sin(azimuth), std::cos(tilt),
                                       std::sin(tilt) * std::cos(azimuth));
    const glm::dvec3 aside(0.16 * std::cos(3.0 * azimuth), 0.0, 0.11 * std::sin(2.0 * azimuth));
    renderer::FrameCamera c;
    c.position = glm::vec3(from);
    c.look_at = glm::vec3(centre + aside);
    CameraPose pose = pose_of(c);
    pose.position = from;
    views.push_back(
        test::frame(test::charuco_view(board, lens, pose, {kWidth, kHeight}), 0.5, random));
  }
  return views;
}

// The views both tests fit, drawn once (a view at 8x8 supersampling, then
// through the lens, takes most of a second).
const std::vector<cv::Mat> &views_of_simulated_lens() {
  static const std::vector<cv::Mat> views = board_views(simulated_lens(), 18);
  return views;
}

TEST(CalibrateCamera, RecoversTheSimulatedLens) {
  const CameraModel lens = simulated_lens();
  const std::vector<cv::Mat> &views = views_of_simulated_lens();
  std::vector<LumaImage> lumas;
  for (const cv::Mat &v : views)
    lumas.push_back({v.data, v.cols, v.rows, std::ptrdiff_t(v.step)});
  const CameraCalibration fit = calibrate_camera(test::floor_board(), lumas);
  const CameraModel &c = fit.camera;
  int used = 0;
  for (const CalibrationView &v : fit.views)
    used += v.used ? 1 : 0;
  std::printf("%d of %zu views, RMS %.3f px: fx %.2f fy %.2f cx %.2f cy %.2f k1 %.5f k2 %.5f "
              "p1 %.6f p2 %.6f k3 %.5f\n",
              used, views.size(), fit.rms_px, c.fx, c.fy, c.cx, c.cy, c.distortion[0],
              c.distortion[1], c.distortion[2], c.distortion[3], c.distortion[4]);
  EXPECT_GE(used, 12);
  EXPECT_LT(fit.rms_px, 0.1);
  EXPECT_NEAR(c.distortion[0], lens.distortion[0], 0.02 * std::abs(lens.distortion[0]));
  EXPECT_NEAR(c.fx, lens.fx, 0.003 * lens.fx);
  EXPECT_NEAR(c.fy, lens.fy, 0.003 * lens.fy);
  // The principal point is the loosest of the parameters: eighteen views
  // place it within a pixel or so (here 1.1 and 0.2 px).
  EXPECT_NEAR(c.cx, lens.cx, 2.0);
  EXPECT_NEAR(c.cy, lens.cy, 2.0);
}

// The command, as a user runs it: PNG views, the example prime's profile,
// the focus it was at. The profile becomes version 3 and gives the fitted
// lens back at that focus; a failing run (too few views) leaves it whole,
// and one whose --at the profile cannot take says so before the fit.
TEST(CalibrateCamera, TheCommandWritesTheCameraIntoTheProfile) {
  const camhead::test::ScratchDir scratch;
  const fs::path &dir = scratch.path();
  const CameraModel lens = simulated_lens();
  std::vector<std::string> names;
  const std::vector<cv::Mat> &views = views_of_simulated_lens();
  for (std::size_t k = 0; k < views.size(); ++k) {
    names.push_back((dir / ("view_" + std::to_string(k) + ".png")).string());
    // Grey, in sRGB bytes as a camera writes them: the PNG's bytes are the
    // view's.
    renderer::Image image(kWidth, kHeight, 3);
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x)
        for (int c = 0; c < 3; ++c)
          image.data[(std::size_t(y) * kWidth + std::size_t(x)) * 3 + std::size_t(c)] =
              renderer::srgb_to_linear(float(views[k].at<std::uint8_t>(y, x)) / 255.0f);
    renderer::write_image(names.back(), image);
  }
  { std::ofstream(dir / "floor.json") << test::kFloorBoardJson; }
  const fs::path profile = dir / "lens.json";
  fs::copy_file(fs::path(CAMHEAD_SOURCE_DIR) / "scenes/lenses/example_35mm.json", profile);
  const auto run = [&](const std::vector<std::string> &files,
                       const std::string &at = "focus=9400 --sensor-width-mm 36") {
    std::string command = CAMHEAD_BINARY " calibrate camera";
    for (const std::string &f : files)
      command += " '" + f + "'";
    command += " --board '" + (dir / "floor.json").string() + "' --profile '" + profile.string() +
               "' --at " + at + " > '" + (dir / "out.txt").string() + "' 2>&1";
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  const auto text_of = [](const fs::path &p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };

  const std::string before = text_of(profile);
  // A zoom point for a prime, and no sensor width for a profile without a
  // camera model: refused before the fit starts.
  for (const std::string at : {"focus=9400,zoom=0 --sensor-width-mm 36", "focus=9400"}) {
    EXPECT_EQ(run(names, at), 2) << at << ": " << text_of(dir / "out.txt");
    const std::string out = text_of(dir / "out.txt");
    EXPECT_NE(out.find(at == "focus=9400" ? "--sensor-width-mm" : "is a prime"), std::string::npos)
        << out;
    EXPECT_EQ(out.find("views of"), std::string::npos) << at << ": the fit started\n" << out;
  }
  EXPECT_EQ(run({names[0], names[1]}), 3) << text_of(dir / "out.txt");
  EXPECT_NE(text_of(dir / "out.txt").find("views with the board usable, 4 needed"),
            std::string::npos)
      << text_of(dir / "out.txt");
  EXPECT_EQ(text_of(profile), before) << "a failed run changed the profile";

  ASSERT_EQ(run(names), 0) << text_of(dir / "out.txt");
  std::printf("%s", text_of(dir / "out.txt").c_str());
  const lens_control::LensProfile p = lens_control::LensProfile::load(profile);
  ASSERT_TRUE(p.has_camera_model());
  lens_control::LensCounts counts;
  counts.focus = lens_control::AxisReading{9400.0, 0, true}; // 2 m
  const lens_control::LensState s = p.evaluate(counts);
  ASSERT_TRUE(s.distortion);
  EXPECT_NEAR(s.distortion->k1, lens.distortion[0], 0.02 * std::abs(lens.distortion[0]));
  EXPECT_NEAR(s.projection.principal_x, (lens.cx + 0.5) / kWidth, 2.0 / kWidth);
  EXPECT_NEAR(s.projection_focal_length_mm.value, lens.fx * 36.0 / kWidth, 0.003 * 36.0);
}

// A Y4M video's frames are views too: their luma planes as stored, spread
// evenly over the views allowed. (Any pictures tell frames apart: noise.)
TEST(CalibrateCamera, AVideosFramesAreViews) {
  const camhead::test::ScratchDir scratch;
  std::vector<cv::Mat> views;
  cv::RNG random(5);
  for (int k = 0; k < 18; ++k) {
    views.emplace_back(kHeight, kWidth, CV_8UC1);
    random.fill(views.back(), cv::RNG::UNIFORM, 0, 256);
  }
  std::string y4m = "YUV4MPEG2 W" + std::to_string(kWidth) + " H" + std::to_string(kHeight) +
                    " F25:1 Ip A1:1 C420jpeg\n";
  const std::string chroma(std::size_t(kWidth / 2) * (kHeight / 2) * 2, char(128));
  for (const cv::Mat &v : views)
    y4m += "FRAME\n" + std::string(reinterpret_cast<const char *>(v.data), v.total()) + chroma;
  const fs::path video = scratch.write("take.y4m", y4m);
  const std::vector<CalibrationPicture> all = read_calibration_views({video}, 40);
  ASSERT_EQ(all.size(), views.size());
  for (std::size_t k = 0; k < views.size(); ++k)
    EXPECT_TRUE(std::equal(all[k].luma.begin(), all[k].luma.end(), views[k].data)) << k;
  const std::vector<CalibrationPicture> some = read_calibration_views({video}, 6);
  ASSERT_EQ(some.size(), 6u);
  EXPECT_EQ(some[1].name, "take.y4m frame 3");
  EXPECT_TRUE(std::equal(some[5].luma.begin(), some[5].luma.end(), views[15].data));
  // Their codes are decoded to light over the range the header states:
  // 16-235 where it states none, as Y4M video most often is.
  EXPECT_TRUE(all[0].image().limited_range);
  std::string full = y4m;
  full.insert(full.find('\n'), " XCOLORRANGE=FULL");
  EXPECT_FALSE(
      read_calibration_views({scratch.write("full.y4m", full)}, 1)[0].image().limited_range);
  // Cut short: refused by name.
  const fs::path cut = scratch.write("cut.y4m", y4m.substr(0, y4m.size() - 1000));
  try {
    (void)read_calibration_views({cut}, 40);
    FAIL() << "read a video cut short";
  } catch (const CalibrationViewError &e) {
    EXPECT_NE(std::string(e.what()).find("cut.y4m: frame 17 is cut short"), std::string::npos)
        << e.what();
  }
}

} // namespace
} // namespace camhead::pipeline
