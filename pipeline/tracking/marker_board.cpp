#include "marker_board.h"

#include <cmath>
#include <set>

#include <glm/geometric.hpp>

#include "camhead/base/config_error.h"
#include "camhead/base/config_json.h"

namespace camhead::pipeline {
namespace {

using base::JsonValue;
using base::Range;

constexpr std::string_view kFormat = "camhead-markers";

glm::dvec3 vec3(const JsonValue &v) {
  const std::vector<double> xs = v.numbers(3);
  return {xs[0], xs[1], xs[2]};
}

int read_dictionary(const JsonValue &v) {
  const std::string name = v.string();
  const std::vector<MarkerDictionary> &all = marker_dictionaries();
  std::string names;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (all[i].name == name)
      return int(i);
    names += (i == 0 ? "" : ", ") + std::string(all[i].name);
  }
  v.fail("unknown dictionary \"" + name + "\" (OpenCV's: " + names + ")");
}

// A field marker's corners from its centre, the normal of its printed face
// and the direction of its top: OpenCV's order, seen facing the marker.
PlacedMarker place(const JsonValue &d, double side) {
  d.object({"id", "center", "normal"}, {"up"});
  PlacedMarker m;
  m.id = int(d.at("id").integer(0, 4095));
  const glm::dvec3 center = vec3(d.at("center"));
  const glm::dvec3 normal = vec3(d.at("normal"));
  if (!(glm::length(normal) > 1e-9))
    d.at("normal").fail("must not be zero");
  const glm::dvec3 n = glm::normalize(normal);
  glm::dvec3 up = d.has("up") ? vec3(d.at("up")) : glm::dvec3(0.0, 1.0, 0.0);
  up -= glm::dot(up, n) * n; // the part of it in the marker's plane
  if (!(glm::length(up) > 1e-6))
    d.fail_member("up", d.has("up") ? "parallel to the normal"
                                    : "missing, and the default [0, 1, 0] is parallel to the "
                                      "normal (a marker on the floor or the ceiling): give the "
                                      "direction its top points to");
  up = glm::normalize(up);
  const glm::dvec3 right = glm::cross(up, n);
  const double h = side / 2.0;
  m.corners = {center + h * (up - right), center + h * (up + right), center + h * (right - up),
               center - h * (up + right)};
  return m;
}

MarkerBoard read(const JsonValue &root, const std::filesystem::path &file) {
  const JsonValue format = root.at("format");
  if (!format.json().is_string() || format.json().get<std::string>() != kFormat)
    format.fail("must be \"" + std::string(kFormat) + "\"");
  const JsonValue version = root.at("version");
  if (!version.json().is_number_integer() || version.json().get<std::int64_t>() != 1)
    version.fail("unsupported version (this reader understands 1)");
  MarkerBoard board;
  board.file = file;
  const std::string type = root.at("type", "charuco or field").string({"charuco", "field"});
  if (type == "charuco") {
    root.object(
        {"format", "version", "name", "type", "dictionary", "squares", "square_m", "marker_m"});
    board.type = MarkerBoardType::charuco;
    const JsonValue squares = root.at("squares");
    const std::vector<double> xy = squares.numbers(2, Range::within(2.0, 100.0));
    if (xy[0] != std::floor(xy[0]) || xy[1] != std::floor(xy[1]))
      squares.fail("must be two whole numbers of squares, [across, down]");
    board.squares_x = int(xy[0]);
    board.squares_y = int(xy[1]);
    board.square_m = root.at("square_m").number(Range::above(0.0, 10.0));
    board.marker_m = root.at("marker_m").number(Range::above(0.0, 10.0));
    if (board.marker_m >= board.square_m)
      root.fail_member("marker_m", "must be smaller than square_m (the marker sits inside its "
                                   "white square)");
  } else {
    root.object({"format", "version", "name", "type", "dictionary", "marker_m", "markers"});
    board.type = MarkerBoardType::field;
    board.marker_m = root.at("marker_m").number(Range::above(0.0, 10.0));
    const std::vector<JsonValue> markers = root.at("markers").elements("markers");
    if (markers.empty())
      root.at("markers").fail("must list at least one marker");
    std::set<int> ids;
    for (const JsonValue &m : markers) {
      board.markers.push_back(place(m, board.marker_m));
      if (!ids.insert(board.markers.back().id).second)
        m.fail_member("id", std::to_string(board.markers.back().id) +
                                " is given twice: each printed marker once");
    }
  }
  board.name = root.at("name").string();
  const JsonValue dictionary = root.at("dictionary");
  board.dictionary = read_dictionary(dictionary);
  const int available = marker_dictionaries()[std::size_t(board.dictionary)].markers;
  if (board.type == MarkerBoardType::charuco) {
    const int needed = board.squares_x * board.squares_y / 2;
    if (needed > available)
      dictionary.fail("has " + std::to_string(available) + " markers; a " +
                      std::to_string(board.squares_x) + "x" + std::to_string(board.squares_y) +
                      " board needs " + std::to_string(needed));
  }
  for (std::size_t i = 0; i < board.markers.size(); ++i)
    if (board.markers[i].id >= available)
      root.at("markers").elements()[i].at("id").fail("must be below " + std::to_string(available) +
                                                     ", the markers of " + dictionary.string());
  return board;
}

} // namespace

const std::vector<MarkerDictionary> &marker_dictionaries() {
  static const std::vector<MarkerDictionary> all = {
      {"4X4_50", 50},        {"4X4_100", 100},         {"4X4_250", 250},
      {"4X4_1000", 1000},    {"5X5_50", 50},           {"5X5_100", 100},
      {"5X5_250", 250},      {"5X5_1000", 1000},       {"6X6_50", 50},
      {"6X6_100", 100},      {"6X6_250", 250},         {"6X6_1000", 1000},
      {"7X7_50", 50},        {"7X7_100", 100},         {"7X7_250", 250},
      {"7X7_1000", 1000},    {"ARUCO_ORIGINAL", 1024}, {"APRILTAG_16h5", 30},
      {"APRILTAG_25h9", 35}, {"APRILTAG_36h10", 2320}, {"APRILTAG_36h11", 587}};
  return all;
}

MarkerBoard parse_marker_board(std::string_view json_text, const std::filesystem::path &file) {
  try {
    const base::JsonFile json(json_text, file.string());
    return read(json.root(), file);
  } catch (const MarkerBoardError &) {
    throw;
  } catch (const base::ConfigError &e) {
    throw MarkerBoardError(e);
  }
}

MarkerBoard load_marker_board(const std::filesystem::path &file) {
  std::string text;
  try {
    text = base::read_config_file(file); // bounded; a folder refused
  } catch (const base::ConfigError &e) {
    throw MarkerBoardError(e);
  }
  return parse_marker_board(text, file);
}

} // namespace camhead::pipeline
