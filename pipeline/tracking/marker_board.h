// Marker-board files: the printed targets the marker pose source finds in
// the camera's picture, and where they are in the scene's world.
//
//   {"format": "camhead-markers", "version": 1, "name": "floor board",
//    "type": "charuco", "dictionary": "5X5_100",
//    "squares": [7, 5], "square_m": 0.08, "marker_m": 0.06}
//
//   {"format": "camhead-markers", "version": 1, "name": "studio",
//    "type": "field", "dictionary": "4X4_50", "marker_m": 0.2,
//    "markers": [{"id": 3, "center": [0, 1.5, -4], "normal": [0, 0, 1], "up": [0, 1, 0]}]}
//
// A ChArUco board (OpenCV 4.6's layout: origin at the printed page's top
// left outer corner, x to the right, y down the page) lies face up on the
// scene's floor with its origin at the world origin: its x along the
// world's x, its y along the world's +z, so that a camera at rest (looking
// along -z) over the board's bottom edge reads it upright; a virtual object
// at (0, 0, 0) stands on the board's corner. A marker field gives each marker where it
// was measured in the world: its centre, the normal its printed face looks
// along and the direction its top points to.
//
// Plain data and its reader only: no OpenCV here (the tracking module has
// it; tracking/marker_module.h). The reader checks every field and throws
// MarkerBoardError("FILE: FIELD: REASON").
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "camhead/base/config_error.h"

namespace camhead::pipeline {

class MarkerBoardError : public base::ConfigError {
public:
  using base::ConfigError::ConfigError;
  explicit MarkerBoardError(const base::ConfigError &e) : base::ConfigError(e) {}
};

// OpenCV's predefined ArUco dictionaries (cv::aruco::PREDEFINED_DICTIONARY_NAME,
// in its order, so that the index is the enum's value).
struct MarkerDictionary {
  std::string_view name; // "4X4_50", as board files spell it
  int markers;           // how many ids it has
};
[[nodiscard]] const std::vector<MarkerDictionary> &marker_dictionaries();

enum class MarkerBoardType { charuco, field };

// One marker of a field: its corners in the world, in OpenCV's order (top
// left, top right, bottom right, bottom left, seen facing the marker).
struct PlacedMarker {
  int id = 0;
  std::array<glm::dvec3, 4> corners;
};

struct MarkerBoard {
  std::string name;
  std::filesystem::path file;
  MarkerBoardType type = MarkerBoardType::charuco;
  int dictionary = 0; // index into marker_dictionaries()
  // ChArUco: squares along x and y, their side and the markers' side.
  int squares_x = 0, squares_y = 0;
  double square_m = 0.0;
  double marker_m = 0.0;             // a field's markers' side too
  std::vector<PlacedMarker> markers; // a field's
};

// The world point of a point (x, y) on a ChArUco board's face (OpenCV's
// board coordinates, metres; its z, into the page, is the world's -y).
[[nodiscard]] inline glm::dvec3 board_to_world(double x, double y) {
  return {x, 0.0, y};
}

[[nodiscard]] MarkerBoard load_marker_board(const std::filesystem::path &file);
[[nodiscard]] MarkerBoard parse_marker_board(std::string_view json_text,
                                             const std::filesystem::path &file);

} // namespace camhead::pipeline
