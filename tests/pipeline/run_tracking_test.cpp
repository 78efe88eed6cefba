// A tracker's pose moves the camera of `camhead run` (issue 25, "What must be
// shown" 6): a FreeD head and an OpenTrackIO tracker each send a pan over
// UDP on this host, and the virtual object lands where that pan puts it in
// the composites, with the pose in the per-frame record, fresh.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "camhead/base/monotonic_clock.h"
#include "run/lens_hub.h"
#include "run/run_loop.h"
#include "run_test_support.h"
#include "tracker_sender.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

constexpr int kWidth = 160;
constexpr int kHeight = 96;
constexpr double kFocalMm = 35.0, kSensorMm = 36.0;

class RunTracking : public RunLoop, public testing::WithParamInterface<const char *> {
protected:
  // A glowing virtual ball 3 m straight ahead of the scene's camera, in a
  // dark real room; the lens a still 35 mm at f/8 focused on the ball, from
  // calibrated values (no profile: they drive it).
  Board tracked_board(const std::string &type, std::uint16_t port) const {
    const fs::path scene =
        write("scene.json", R"({"render": {"width": 160, "height": 96, "samples": 4},
      "camera": {"position": [0, 1, 0], "look_at": [0, 1, -1], "up": [0, 1, 0],
                 "focal_length_mm": 35, "sensor_width_mm": 36, "f_number": 8, "focus_distance_m": 3},
      "materials": {"black": {"type": "diffuse", "albedo": [0, 0, 0]},
                    "glow": {"type": "emission", "radiance": [1, 1, 1]}},
      "objects": [
        {"name": "wall", "type": "plane", "center": [0, 1, -8], "size": [40, 40],
         "rotation_deg": [90, 0, 0], "material": "black", "real": true},
        {"name": "ball", "type": "sphere", "center": [0, 1, -3], "radius": 0.15,
         "material": "glow", "real": false}],
      "lights": []})");
    const fs::path lens = write("lens.csv", "# camhead lens trace v1\n"
                                            "t_s,focus_m,f_stop,focal_mm\n"
                                            "0,3,8,35\n0.5,3,8,35\n1,3,8,35\n");
    return load_board(write("board.json", R"({"format": "camhead-board", "version": 1,
      "name": "tracked", "lens": {"sources": [
        {"name": "still", "type": "trace", "file": ")" +
                                              lens.string() + R"(", "loop": true},
        {"name": "tracker", "type": ")" + type +
                                              R"(", "bind": "127.0.0.1", "port": )" +
                                              std::to_string(port) + R"(}]},
      "camera": {"type": "sim", "width": 160, "height": 96, "fps": 10, "samples": 4,
                 "cache_mb": 0},
      "scene": ")" + scene.string() + R"(",
      "pose": {"type": ")" + type + R"("},
      "render": {"rays_per_pixel": 16}})"));
  }

  struct Measured {
    std::vector<double> ball_x;    // the ball's centroid column in each fresh composite, px
    std::vector<double> forward_x; // the recorded view direction's x, likewise
    std::size_t composites = 0;
    // The composites before the tracker's first pose, and the light above
    // black in them (the room is black: the ball's).
    std::size_t before_first = 0;
    double light_before_first = 0.0;
  };

  // Runs the rig while the tracker sends `pan_deg`; none sends without.
  Measured run_with_pan(const std::string &type, std::optional<double> pan_deg) const {
    const std::uint16_t port = free_udp_port();
    RunOptions options;
    options.board = tracked_board(type, port);
    options.outputs = {"file:" + (dir_ / "out.y4m").string()};
    options.stats_file = dir_ / "stats.jsonl";
    options.frames = 6;
    options.duration_s = 120.0;
    options.status = nullptr;
    RunSummary summary;
    {
      std::optional<Tracker> tracker;
      if (pan_deg)
        tracker.emplace(type, port, *pan_deg);
      summary = run_pipeline(options);
    }
    EXPECT_GE(summary.frames_out, 4u);
    const std::vector<std::string> frames =
        y4m_frames(dir_ / "out.y4m", std::size_t(kWidth) * kHeight * 2);
    Measured m;
    std::ifstream stats(dir_ / "stats.jsonl");
    for (std::string line; std::getline(stats, line);) {
      if (line.find("\"kind\":\"composite\"") == std::string::npos)
        continue;
      ++m.composites;
      EXPECT_NE(line.find("\"pose_source\":\"" + type + ":tracker\""), std::string::npos) << line;
      const auto output_frame = std::size_t(json_number(line, "output_frame"));
      EXPECT_LT(output_frame, frames.size());
      if (output_frame >= frames.size())
        continue;
      // The luma plane (first in planar 4:2:2); the room is black.
      double sum = 0.0, weighted = 0.0;
      for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
          const double v = std::max(
              0.0, double(std::uint8_t(frames[output_frame][std::size_t(y * kWidth + x)])) - 16.0);
          sum += v;
          weighted += v * x;
        }
      if (line.find("\"pose_known\":false") != std::string::npos) {
        EXPECT_NE(line.find("\"pose_fresh\":false"), std::string::npos) << line;
        ++m.before_first;
        m.light_before_first += sum;
        continue;
      }
      if (line.find("\"pose_fresh\":true") == std::string::npos)
        continue; // held
      const std::size_t forward = line.find("\"forward\":[");
      EXPECT_NE(forward, std::string::npos) << line;
      m.forward_x.push_back(std::stod(line.substr(forward + 11)));
      EXPECT_GT(sum, 0.0) << "the ball is in the picture";
      m.ball_x.push_back(sum > 0.0 ? weighted / sum + 0.5 : 0.0); // pixel centres
    }
    return m;
  }
};

TEST_P(RunTracking, APanMovesTheVirtualObjectWhereTheLensPutsIt) {
  const std::string type = GetParam();
  // FreeD pans right for a positive pan, OpenTrackIO left (tracker_axes.h):
  // a ball straight ahead moves the other way in the picture.
  const double pan_deg = 4.0, turn_right_deg = type == "freed" ? pan_deg : -pan_deg;
  const double f_px = kFocalMm / kSensorMm * kWidth;
  const double expected_x =
      kWidth / 2.0 - f_px * std::tan(turn_right_deg * std::numbers::pi / 180.0);

  const Measured still = run_with_pan(type, 0.0);
  const Measured panned = run_with_pan(type, pan_deg);
  for (const Measured *m : {&still, &panned}) {
    EXPECT_GE(m->ball_x.size(), 2u)
        << "of " << m->composites << " composites, too few had the tracker's pose fresh";
    EXPECT_EQ(m->light_before_first, 0.0) << "before the first pose, the camera image alone";
  }
  for (const double x : still.ball_x)
    EXPECT_NEAR(x, kWidth / 2.0, 0.25) << "pan 0: the ball dead ahead";
  for (const double x : panned.ball_x) {
    std::printf("%s pan %.0f: ball at %.3f px, the pinhole formula %.3f px\n", type.c_str(),
                pan_deg, x, expected_x);
    EXPECT_NEAR(x, expected_x, 0.25) << type << " pan " << pan_deg;
  }
  for (const double fx : panned.forward_x)
    EXPECT_NEAR(fx, std::sin(turn_right_deg * std::numbers::pi / 180.0), 1e-5)
        << "the recorded view";
}

// Before the tracker's first pose the frames are the camera image alone:
// drawn from the scene's camera, the ball would stand dead ahead (as the
// frames of a tracker at pan 0, above, show it).
TEST_P(RunTracking, BeforeTheFirstPoseTheFramesAreTheCameraImage) {
  const Measured silent = run_with_pan(GetParam(), std::nullopt);
  EXPECT_GE(silent.composites, 4u);
  EXPECT_EQ(silent.before_first, silent.composites);
  EXPECT_EQ(silent.light_before_first, 0.0) << "the ball must not show";
}

// An instant before the tracker's first pose stays before it once poses
// have come: a frame of that instant, rendered late, would otherwise take
// the first pose held back (PoseAt::before_first).
TEST_P(RunTracking, AnInstantBeforeTheFirstPoseStaysBeforeIt) {
  const std::uint16_t port = free_udp_port();
  LensHub lens(tracked_board(GetParam(), port));
  const std::int64_t before_ns = base::monotonic_ns();
  lens.start();
  const Tracker tracker(GetParam(), port, 2.0);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  PoseSnapshot now = lens.pose_at(base::monotonic_ns(), CameraPose{});
  while (!now.known && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    now = lens.pose_at(base::monotonic_ns(), CameraPose{});
  }
  ASSERT_TRUE(now.known) << "no pose from the tracker in 10 s";
  const PoseSnapshot earlier = lens.pose_at(before_ns, CameraPose{});
  EXPECT_FALSE(earlier.known);
  EXPECT_FALSE(earlier.fresh);
}

INSTANTIATE_TEST_SUITE_P(Trackers, RunTracking, testing::Values("freed", "opentrackio"),
                         [](const testing::TestParamInfo<const char *> &tracker) {
                           return std::string(tracker.param);
                         });

} // namespace
} // namespace camhead::pipeline
