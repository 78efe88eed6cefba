// Where one of camhead's own modules is: a shared object that camhead opens
// at run time rather than links (the libcamera camera, the marker tracker),
// so that the binary starts where the module's library is not installed.
#pragma once

#include <string>
#include <vector>

namespace camhead::hal {

struct ModuleSearch {
  std::vector<std::string> candidates; // in the order to try them
  std::string searched;                // where they were looked for, for messages
};

// `env_var`'s path if it is set (and nothing else); else `file_name` beside
// the executable (a build tree: build/camhead), in `reldir` relative to it
// (an install's lib folder from its bin), each where it exists, then the
// bare name, which dlopen looks up on the library path.
[[nodiscard]] ModuleSearch module_search(const char *env_var, const char *file_name,
                                         const char *reldir);

// Whether `error` (SharedLibrary::error()) says no more than that the bare
// `file_name` is not on the library path: the module is not installed, as
// opposed to a file that exists but does not load.
[[nodiscard]] bool module_not_installed(const std::string &error, const char *file_name);

} // namespace camhead::hal
