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

// The boards an administrator keeps, which a board's name finds before the
// data folder's board/ (resolve_board()): $CAMHEAD_CONFIG_DIR/board where
// that is set, else /etc/camhead/board for an installed camhead (its data
// folder EXE_DIR/../share/camhead: the package ships its boards there as
// conffiles, which an upgrade leaves as the administrator edited them).
// Empty for a camhead run from its build tree or a copied binary, which see
// only their own board/.
[[nodiscard]] std::filesystem::path config_board_dir();

// Where a board file's relative paths start: the data folder's board/ for
// a board in config_board_dir() (so that a copy of a shipped board finds
// the scenes and lens files beside the shipped one); empty for any other,
// whose paths start from its own folder.
[[nodiscard]] std::filesystem::path board_paths_folder(const std::filesystem::path &board_file);

// What was searched, one folder a line, for the message when nothing matched.
[[nodiscard]] std::string describe_data_dir_search();

} // namespace camhead::pipeline
