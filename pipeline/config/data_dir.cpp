#include "config/data_dir.h"

#include <cstdlib>
#include <system_error>

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;

fs::path executable_dir() {
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  return error ? fs::path() : exe.parent_path();
}

bool holds_data(const fs::path &dir) {
  std::error_code error;
  return fs::is_regular_file(dir / "board" / "sim.json", error);
}

} // namespace

std::vector<fs::path> data_dir_candidates() {
  std::vector<fs::path> candidates;
  if (const char *env = std::getenv("CAMHEAD_DATA_DIR"); env != nullptr && *env != '\0')
    candidates.emplace_back(env);
  if (const fs::path exe = executable_dir(); !exe.empty()) {
    candidates.push_back((exe / ".." / "share" / "camhead").lexically_normal());
    candidates.push_back(exe.parent_path());
    candidates.push_back(exe);
  }
  candidates.emplace_back(CAMHEAD_SOURCE_DATA_DIR);
  return candidates;
}

fs::path data_dir() {
  // An explicit CAMHEAD_DATA_DIR is taken as it is: a wrong one must show up
  // as "board/sim.json cannot be opened" under that folder, not be skipped.
  if (const char *env = std::getenv("CAMHEAD_DATA_DIR"); env != nullptr && *env != '\0')
    return env;
  for (const fs::path &dir : data_dir_candidates())
    if (holds_data(dir))
      return dir;
  return {};
}

fs::path config_board_dir() {
  if (const char *env = std::getenv("CAMHEAD_CONFIG_DIR"); env != nullptr && *env != '\0')
    return fs::path(env) / "board";
  if (std::getenv("CAMHEAD_DATA_DIR") != nullptr)
    return {}; // a data folder given by hand: its boards alone
  const fs::path exe = executable_dir();
  std::error_code error;
  if (exe.empty() || !fs::equivalent(data_dir(), exe / ".." / "share" / "camhead", error))
    return {};
  return "/etc/camhead/board";
}

fs::path board_paths_folder(const fs::path &board_file) {
  const fs::path config = config_board_dir();
  std::error_code error;
  if (!config.empty() &&
      fs::equivalent(fs::absolute(board_file, error).parent_path(), config, error))
    if (const fs::path data = data_dir(); !data.empty())
      return data / "board";
  return {};
}

std::string describe_data_dir_search() {
  std::string text;
  for (const fs::path &dir : data_dir_candidates())
    text += "  " + dir.string() + "\n";
  return text;
}

} // namespace camhead::pipeline
