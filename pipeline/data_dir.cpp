#include "data_dir.h"

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

std::string describe_data_dir_search() {
  std::string text;
  for (const fs::path &dir : data_dir_candidates())
    text += "  " + dir.string() + "\n";
  return text;
}

} // namespace camhead::pipeline
