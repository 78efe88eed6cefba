// See gpiod_library.h.
#include "gpiod_library.h"

#include <cstdio>
#include <cstdlib>

#include "camhead/hal/shared_library.h"

namespace camhead::hal::lens::gpio::detail {
namespace {

struct LoadedGpiod {
  // Kept open for the life of the process, like a linked library.
  SharedLibrary library{CAMHEAD_GPIOD_SONAME, "libgpiod2"};
  GpiodFunctions functions;

  LoadedGpiod() {
#define CAMHEAD_GPIOD_RESOLVE(name) library.resolve("gpiod_" #name, functions.name);
    CAMHEAD_GPIOD_FUNCTIONS(CAMHEAD_GPIOD_RESOLVE)
#undef CAMHEAD_GPIOD_RESOLVE
  }
};

const LoadedGpiod &loaded() {
  static const LoadedGpiod instance;
  return instance;
}

} // namespace

const std::string &gpiod_load_error() {
  return loaded().library.error();
}

const GpiodFunctions &gpiod() {
  if (!loaded().library.ok()) {
    std::fprintf(stderr, "camhead: libgpiod called without checking: %s\n",
                 loaded().library.error().c_str());
    std::abort();
  }
  return loaded().functions;
}

} // namespace camhead::hal::lens::gpio::detail
