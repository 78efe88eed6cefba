// Marker-board files: a ChArUco board and a marker field read with their
// geometry, and every mistake refused with the file and field named.
#include <filesystem>
#include <string>

#include <glm/geometric.hpp>

#include "tracking/marker_board.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

std::string error_of(const std::string &json) {
  try {
    static_cast<void>(parse_marker_board(json, "/rigs/floor.json"));
  } catch (const MarkerBoardError &e) {
    return e.what();
  }
  return "(no error)";
}

std::string charuco(const std::string &fields) {
  return R"({"format": "camhead-markers", "version": 1, "name": "floor", "type": "charuco", )" +
         fields + "}";
}

std::string field(const std::string &markers, const std::string &extra = "") {
  return R"({"format": "camhead-markers", "version": 1, "name": "studio", "type": "field",
             "dictionary": "4X4_50", "marker_m": 0.2, "markers": [)" +
         markers + "]" + extra + "}";
}

TEST(MarkerBoard, ACharucoBoardIsReadWithItsGeometry) {
  const MarkerBoard b = parse_marker_board(
      charuco(R"("dictionary": "5X5_100", "squares": [7, 5], "square_m": 0.12, "marker_m": 0.09)"),
      "b.json");
  EXPECT_EQ(b.type, MarkerBoardType::charuco);
  EXPECT_EQ(b.name, "floor");
  EXPECT_EQ(marker_dictionaries()[std::size_t(b.dictionary)].name, "5X5_100");
  EXPECT_EQ(b.dictionary, 5) << "OpenCV's DICT_5X5_100";
  EXPECT_EQ(b.squares_x, 7);
  EXPECT_EQ(b.squares_y, 5);
  EXPECT_EQ(b.square_m, 0.12);
  EXPECT_EQ(b.marker_m, 0.09);
  // Face up on the floor, the page's y towards a camera at rest.
  EXPECT_EQ(board_to_world(0.5, 0.25), glm::dvec3(0.5, 0.0, 0.25));
}

TEST(MarkerBoard, AFieldsMarkersHaveTheirCornersInOpenCvsOrder) {
  // On the wall ahead, facing the camera (normal +z), top up: seen from the
  // front, top left is at -x, +y.
  const MarkerBoard b =
      parse_marker_board(field(R"({"id": 7, "center": [1, 1.5, -4], "normal": [0, 0, 2]},
               {"id": 9, "center": [0, 0, -2], "normal": [0, 1, 0], "up": [0, 0, -1]})"),
                         "f.json");
  ASSERT_EQ(b.markers.size(), 2u);
  EXPECT_EQ(b.markers[0].id, 7);
  const auto &c = b.markers[0].corners;
  EXPECT_EQ(c[0], glm::dvec3(0.9, 1.6, -4));
  EXPECT_EQ(c[1], glm::dvec3(1.1, 1.6, -4));
  EXPECT_EQ(c[2], glm::dvec3(1.1, 1.4, -4));
  EXPECT_EQ(c[3], glm::dvec3(0.9, 1.4, -4));
  // On the floor, face up, its top away from a camera at rest.
  const auto &f = b.markers[1].corners;
  EXPECT_EQ(f[0], glm::dvec3(-0.1, 0, -2.1));
  EXPECT_EQ(f[2], glm::dvec3(0.1, 0, -1.9));
}

TEST(MarkerBoard, AFileThatCannotBeReadIsNamed) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path();
  try {
    static_cast<void>(load_marker_board(folder));
    ADD_FAILURE() << "a folder loaded";
  } catch (const MarkerBoardError &e) {
    EXPECT_EQ(std::string(e.what()), folder.string() + ": (file): is a folder, not a file");
  }
}

TEST(MarkerBoard, EveryMistakeIsNamed) {
  const std::string file = "/rigs/floor.json: ";
  const std::string ok = R"("squares": [7, 5], "square_m": 0.12, "marker_m": 0.09)";
  EXPECT_EQ(error_of(charuco(R"("dictionary": "5x5_100", )" + ok)),
            file + "dictionary: unknown dictionary \"5x5_100\" (OpenCV's: 4X4_50, 4X4_100, "
                   "4X4_250, 4X4_1000, 5X5_50, 5X5_100, 5X5_250, 5X5_1000, 6X6_50, 6X6_100, "
                   "6X6_250, 6X6_1000, 7X7_50, 7X7_100, 7X7_250, 7X7_1000, ARUCO_ORIGINAL, "
                   "APRILTAG_16h5, APRILTAG_25h9, APRILTAG_36h10, APRILTAG_36h11)");
  EXPECT_EQ(error_of(charuco(R"("dictionary": "APRILTAG_16h5", "squares": [9, 8],
                                "square_m": 0.1, "marker_m": 0.08)")),
            file + "dictionary: has 30 markers; a 9x8 board needs 36");
  EXPECT_EQ(error_of(charuco(R"("dictionary": "5X5_100", "squares": [7.5, 5],
                                "square_m": 0.12, "marker_m": 0.09)")),
            file + "squares: must be two whole numbers of squares, [across, down]");
  EXPECT_EQ(error_of(charuco(R"("dictionary": "5X5_100", "squares": [7, 5],
                                "square_m": 0.12, "marker_m": 0.12)")),
            file + "marker_m: must be smaller than square_m (the marker sits inside its white "
                   "square)");
  EXPECT_EQ(error_of(charuco(R"("dictionary": "5X5_100", "squares": [7, 5],
                                "square_m": -1, "marker_m": 0.09)")),
            file + "square_m: must be > 0 and <= 10");
  EXPECT_EQ(error_of(R"({"format": "camhead-markers", "version": 1, "name": "x",
                        "type": "grid"})"),
            file + "type: must be one of charuco, field");
  EXPECT_EQ(error_of(field(R"({"id": 7, "center": [0, 1, -4], "normal": [0, 0, 1]},
                              {"id": 7, "center": [1, 1, -4], "normal": [0, 0, 1]})")),
            file + "markers[1].id: 7 is given twice: each printed marker once");
  EXPECT_EQ(error_of(field(R"({"id": 50, "center": [0, 1, -4], "normal": [0, 0, 1]})")),
            file + "markers[0].id: must be below 50, the markers of 4X4_50");
  EXPECT_EQ(error_of(field(R"({"id": 1, "center": [0, 0, -4], "normal": [0, 1, 0]})")),
            file + "markers[0].up: missing, and the default [0, 1, 0] is parallel to the "
                   "normal (a marker on the floor or the ceiling): give the direction its top "
                   "points to");
  EXPECT_EQ(error_of(field(R"({"id": 1, "center": [0, 0, -4], "normal": [0, 0, 0]})")),
            file + "markers[0].normal: must not be zero");
  EXPECT_EQ(error_of(field("")), file + "markers: must list at least one marker");
  EXPECT_EQ(error_of(field(R"({"id": 1, "center": [0, 0, -4], "normal": [0, 0, 1]})",
                           R"(, "squares": [2, 2])")),
            file + "squares: unknown field");
}

} // namespace
} // namespace camhead::pipeline
