// See module_search.h.
#include "camhead/hal/module_search.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace camhead::hal {

namespace fs = std::filesystem;

ModuleSearch module_search(const char *env_var, const char *file_name, const char *reldir) {
  ModuleSearch search;
  if (const char *path = std::getenv(env_var); path != nullptr && *path) {
    search.searched = std::string("$") + env_var + " (" + path + ")";
    search.candidates = {path};
    return search;
  }
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    const fs::path dir = exe.parent_path();
    for (const fs::path &place : {dir, dir / reldir}) {
      const fs::path file = (place / file_name).lexically_normal();
      if (fs::exists(file, error))
        search.candidates.push_back(file);
      search.searched += (search.searched.empty() ? "" : ", ") + file.parent_path().string();
    }
  }
  search.candidates.emplace_back(file_name);
  search.searched += (search.searched.empty() ? "" : ", ") + std::string("the library path");
  return search;
}

bool module_not_installed(const std::string &error, const char *file_name) {
  return error.find(std::string(file_name) + ": cannot open shared object file") !=
         std::string::npos;
}

} // namespace camhead::hal
