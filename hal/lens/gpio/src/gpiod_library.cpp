// See gpiod_library.h.
#include "gpiod_library.h"

#include "camhead/hal/shared_library.h"

namespace camhead::hal::lens::gpio::detail {
namespace {

const FunctionTable<GpiodFunctions> &table() {
  // Never destroyed, like a linked library never unloaded: nothing that still
  // runs during exit (a backend's thread, a static's destructor) can find
  // the library gone.
  static const auto *const loaded = new FunctionTable<GpiodFunctions>(
      CAMHEAD_GPIOD_SONAME, "libgpiod2", [](SharedLibrary &library, GpiodFunctions &functions) {
#define CAMHEAD_GPIOD_RESOLVE(name) library.resolve("gpiod_" #name, functions.name);
        CAMHEAD_GPIOD_FUNCTIONS(CAMHEAD_GPIOD_RESOLVE)
#undef CAMHEAD_GPIOD_RESOLVE
      });
  return *loaded;
}

} // namespace

const std::string &gpiod_load_error() {
  return table().error();
}

const GpiodFunctions &gpiod() {
  return table().functions();
}

} // namespace camhead::hal::lens::gpio::detail
