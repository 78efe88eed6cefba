// libFuzzer target for the marker-board reader (pipeline/tracking/
// marker_board.h): any text must be refused with a MarkerBoardError or give a
// board the tracking module can build from: a known dictionary with room for
// the board's markers, a ChArUco board of whole squares whose markers fit
// inside them, a field of distinct ids with finite corners a marker's side
// apart. Any other exception is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <set>

#include <glm/geometric.hpp>

#include "fuzz_check.h"
#include "tracking/marker_board.h"

using camhead::fuzz::check;
using namespace camhead::pipeline;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  try {
    const MarkerBoard board =
        parse_marker_board(camhead::fuzz::text_of(data, size), "fuzz_markers.json");
    check(board.dictionary >= 0 && std::size_t(board.dictionary) < marker_dictionaries().size());
    const int available = marker_dictionaries()[std::size_t(board.dictionary)].markers;
    check(board.marker_m > 0.0 && std::isfinite(board.marker_m));
    if (board.type == MarkerBoardType::charuco) {
      check(board.squares_x >= 2 && board.squares_y >= 2);
      check(board.squares_x * board.squares_y / 2 <= available);
      check(board.marker_m < board.square_m && std::isfinite(board.square_m));
    } else {
      check(!board.markers.empty());
      std::set<int> ids;
      for (const PlacedMarker &m : board.markers) {
        check(m.id >= 0 && m.id < available && ids.insert(m.id).second);
        for (const glm::dvec3 &c : m.corners)
          check(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z));
        const double side = glm::length(m.corners[1] - m.corners[0]);
        check(std::abs(side - board.marker_m) <= 1e-6 * board.marker_m || !std::isfinite(side));
      }
    }
  } catch (const MarkerBoardError &) {
  }
  return 0;
}
