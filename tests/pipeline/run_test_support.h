// What the live-pipeline tests share: a temporary folder with board and
// scene files, and reading back what the pipeline wrote (Y4M frames, the
// per-frame record).
#pragma once

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <unistd.h>

#include "config/board.h"
#include "tracking/camera_pose.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {

namespace fs = std::filesystem;

inline const fs::path kLenses = fs::path(CAMHEAD_SOURCE_DIR) / "scenes" / "lenses";

class RunLoop : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("camhead_run_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string &name, const std::string &text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }

  // A scene of real objects only, lit, at w x h.
  fs::path real_scene(int w, int h) const {
    return write("scene.json", R"({"render": {"width": )" + std::to_string(w) + R"(, "height": )" +
                                   std::to_string(h) + R"(, "samples": 2},
      "camera": {"position": [0, 0.7, 0], "look_at": [0, 0.3, -2], "up": [0, 1, 0],
                 "focal_length_mm": 35, "sensor_width_mm": 36,
                 "f_number": 2, "focus_distance_m": 2},
      "materials": {"grey": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
      "objects": [
        {"name": "floor", "type": "plane", "center": [0, 0, -3], "size": [10, 10], "material": "grey", "real": true},
        {"name": "crate", "type": "box", "center": [0.3, 0.2, -2], "size": [0.4, 0.4, 0.4], "material": "grey", "real": true}],
      "lights": [{"name": "key", "type": "point", "position": [-1, 2, -1], "power_W": 200}]})");
  }

  // A board with the bundled focus pull as its lens (the trace source's
  // fields completed by `source_extra`), `camera`, `scene` and the board
  // fields in `board_extra` (", \"render\": {...}").
  Board board(const std::string &camera, const fs::path &scene,
              const std::string &source_extra = "", const std::string &board_extra = "") const {
    const std::string profile = (kLenses / "example_35mm.json").string();
    const std::string trace = (kLenses / "sim_focus_pull.csv").string();
    return load_board(write("board.json", R"({"format": "camhead-board", "version": 1,
      "name": "t", "lens": {"profile": ")" + profile +
                                              R"(", "sources": [{"type": "trace",
      "file": ")" + trace + "\"" + source_extra +
                                              R"(}]}, "camera": )" + camera + R"(, "scene": ")" +
                                              scene.string() + "\"" + board_extra + "}"));
  }

  fs::path dir_;
};

// Y4M 4:2:2 frames of w x h as the file camera reads them.
inline std::string y4m_422(int w, int h,
                           const std::vector<std::vector<std::uint8_t>> &planar_frames) {
  std::string text = "YUV4MPEG2 W" + std::to_string(w) + " H" + std::to_string(h) +
                     " F25:1 Ip A1:1 C422 XCOLORRANGE=LIMITED\n";
  for (const auto &frame : planar_frames) {
    text += "FRAME\n";
    text.append(reinterpret_cast<const char *>(frame.data()), frame.size());
  }
  return text;
}

// The frames of a Y4M file, each as its planar bytes.
inline std::vector<std::string> y4m_frames(const fs::path &file, std::size_t frame_bytes) {
  std::ifstream in(file, std::ios::binary);
  std::string header;
  std::getline(in, header);
  std::vector<std::string> frames;
  std::string marker;
  while (std::getline(in, marker)) {
    EXPECT_EQ(marker.substr(0, 5), "FRAME");
    std::string bytes(frame_bytes, '\0');
    in.read(bytes.data(), std::streamsize(frame_bytes));
    if (in.gcount() != std::streamsize(frame_bytes))
      break;
    frames.push_back(bytes);
  }
  return frames;
}

// One composite line of the per-frame record.
struct CompositeRecord {
  std::uint64_t output_frame = 0;
  std::uint64_t sequence = 0;
  double exposure_mid_ns = 0.0;
  double delivered_ns = 0.0;
  double focus_m = 0.0;
  bool lens_fresh = false;
  std::uint64_t reprojected_samples = 0;
  bool pose_fresh = false;
};

inline double json_number(const std::string &line, const std::string &field) {
  const std::string key = "\"" + field + "\":";
  const std::size_t at = line.find(key);
  EXPECT_NE(at, std::string::npos) << field << " missing in " << line;
  if (at == std::string::npos)
    return 0.0;
  // The record writes a focus at infinity as null (JSON has no infinity).
  const std::string value = line.substr(at + key.size());
  return value.rfind("null", 0) == 0 ? std::numeric_limits<double>::infinity() : std::stod(value);
}

// A record's three-number array `field` (the pose's position, forward, up).
inline glm::dvec3 json_vec3(const std::string &line, const std::string &field) {
  const std::size_t at = line.find("\"" + field + "\":[");
  EXPECT_NE(at, std::string::npos) << field << " missing in " << line;
  if (at == std::string::npos)
    return glm::dvec3(0.0);
  const char *p = line.c_str() + at + field.size() + 4;
  char *end = nullptr;
  glm::dvec3 v;
  v.x = std::strtod(p, &end);
  v.y = std::strtod(end + 1, &end);
  v.z = std::strtod(end + 1, &end);
  return v;
}

// A record's camera pose ("pose": position, forward, up).
inline CameraPose json_pose(const std::string &line) {
  const glm::dvec3 forward = glm::normalize(json_vec3(line, "forward"));
  const glm::dvec3 right = glm::normalize(glm::cross(forward, json_vec3(line, "up")));
  const glm::dmat3 axes(right, glm::cross(right, forward), -forward); // right, up, back
  return {json_vec3(line, "position"), glm::normalize(glm::quat_cast(axes))};
}

// Where a centred pinhole of `focal_px` at `pose` puts a world point in a
// width x height picture, pixels (centres at +0.5).
inline glm::dvec2 pinhole_pixel(const CameraPose &pose, const glm::dvec3 &point, int width,
                                int height, double focal_px) {
  const glm::dvec3 p = glm::inverse(pose.orientation) * (point - pose.position);
  return {width / 2.0 + focal_px * p.x / -p.z, height / 2.0 - focal_px * p.y / -p.z};
}

// The composites of a --record-stats file, with every field checked there;
// repeats and placeholders (the outputs' other frames) are left out.
inline std::vector<CompositeRecord> recorded_composites(const fs::path &stats) {
  std::vector<CompositeRecord> records;
  std::ifstream in(stats);
  for (std::string line; std::getline(in, line);) {
    if (line.find("\"kind\":\"composite\"") == std::string::npos) {
      EXPECT_TRUE(line.find("\"kind\":\"repeat\"") != std::string::npos ||
                  line.find("\"kind\":\"placeholder\"") != std::string::npos)
          << line;
      continue;
    }
    for (const char *field : {"capture_ns", "delivered_ns", "output_ns", "focus_m", "f_number",
                              "focal_length_mm", "rpp", "dropped_before", "trace_ms"})
      (void)json_number(line, field);
    records.push_back({std::uint64_t(json_number(line, "output_frame")),
                       std::uint64_t(json_number(line, "sequence")),
                       json_number(line, "exposure_mid_ns"), json_number(line, "delivered_ns"),
                       json_number(line, "focus_m"),
                       line.find("\"lens_fresh\":true") != std::string::npos,
                       std::uint64_t(json_number(line, "reprojected_samples")),
                       line.find("\"pose_fresh\":true") != std::string::npos});
  }
  return records;
}

} // namespace camhead::pipeline
