// Opens one of camhead's own modules (module_search.h) and calls its
// factory: the first candidate that loads and has the factory wins; a file
// that exists but does not load, or was built for another camhead, ends the
// search with its reason. Each module's loader keeps what it opened and
// turns the reason into its own error.
#pragma once

#include <memory>
#include <mutex>
#include <string>

#include "camhead/hal/module_search.h"
#include "camhead/hal/shared_library.h"

namespace camhead::hal {

template <class Module> struct LoadedModule {
  std::unique_ptr<SharedLibrary> library; // null when none loaded
  Module *module = nullptr;               // the factory's table, when loaded
  // Why none loaded; empty with no module: found in none of the places.
  std::string error;
};

// Tries `search`'s candidates for `file_name` (its libraries from the Debian
// `packages`), each one's `factory_symbol` called with `abi_version`;
// `what` names the module in the message of a mismatched one ("the
// markers module").
template <class Module>
LoadedModule<Module> load_module(const ModuleSearch &search, const char *file_name,
                                 const char *packages, const char *factory_symbol, int abi_version,
                                 const char *what) {
  LoadedModule<Module> out;
  for (const std::string &path : search.candidates) {
    auto library = std::make_unique<SharedLibrary>(path, packages);
    Module *(*factory)(int) = nullptr;
    library->resolve(factory_symbol, factory);
    if (!library->ok()) {
      out.error = library->error();
      // A bare name that dlopen did not find: not installed, try no more.
      if (path == file_name && module_not_installed(out.error, file_name))
        out.error.clear();
      if (!out.error.empty())
        return out;
      continue;
    }
    out.module = factory(abi_version);
    if (out.module == nullptr) {
      out.error = path + ": built for another camhead (module ABI " + std::to_string(abi_version) +
                  " wanted); rebuild camhead and " + what + " together";
      return out;
    }
    out.library = std::move(library);
    return out;
  }
  return out;
}

// A module opened once and never closed, as the objects it makes run its
// code until the process ends: the first get() that loads it keeps it
// (its library kept reachable, for leak checkers too); until then each
// get() tries again. Meant as a function-local static of its loader.
template <class Module> class ModuleOnce {
public:
  // The module, or null with `loaded` (what load() gave) saying why.
  template <class Load> Module *get(Load load, LoadedModule<Module> &loaded) {
    const std::lock_guard lock(mutex_);
    if (module_ == nullptr) {
      loaded = load();
      if (loaded.module == nullptr)
        return nullptr;
      library_ = loaded.library.release();
      module_ = loaded.module;
    }
    return module_;
  }

private:
  std::mutex mutex_;
  SharedLibrary *library_ = nullptr;
  Module *module_ = nullptr;
};

} // namespace camhead::hal
