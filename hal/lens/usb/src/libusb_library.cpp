// See libusb_library.h.
#include "libusb_library.h"

#include "camhead/hal/shared_library.h"

namespace camhead::hal::lens::detail {
namespace {

const FunctionTable<LibusbFunctions> &table() {
  // Never destroyed, like a linked library never unloaded: nothing that still
  // runs during exit (a backend's thread, a static's destructor) can find
  // the library gone.
  static const auto *const loaded =
      new FunctionTable<LibusbFunctions>(CAMHEAD_LIBUSB_SONAME, "libusb-1.0-0",
                                         [](SharedLibrary &library, LibusbFunctions &functions) {
#define CAMHEAD_LIBUSB_RESOLVE(name) library.resolve("libusb_" #name, functions.name);
                                           CAMHEAD_LIBUSB_FUNCTIONS(CAMHEAD_LIBUSB_RESOLVE)
#undef CAMHEAD_LIBUSB_RESOLVE
                                         });
  return *loaded;
}

} // namespace

const std::string &libusb_load_error() {
  return table().error();
}

const LibusbFunctions &libusb() {
  return table().functions();
}

} // namespace camhead::hal::lens::detail
