// Where camhead finds its data (board/, scenes/, scenes/lenses/): beside the
// binary, wherever the binary was copied or installed, not where it was built.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace camhead::pipeline {

// The folders data_dir() tries, first match wins:
//   $CAMHEAD_DATA_DIR                      (as given, whether or not it exists)
//   EXE_DIR/../share/camhead               (an installed camhead: cmake --install)
//   EXE_DIR/..                             (build/camhead inside the source tree)
//   EXE_DIR                                (a binary copied next to board/ and scenes/)
//   the source tree the binary was built from (a build folder outside the tree)
// A folder matches when it holds board/sim.json.
[[nodiscard]] std::vector<std::filesystem::path> data_dir_candidates();

// The first candidate that matches, or an empty path when none does.
[[nodiscard]] std::filesystem::path data_dir();

// What was searched, one folder a line, for the message when nothing matched.
[[nodiscard]] std::string describe_data_dir_search();

} // namespace camhead::pipeline
