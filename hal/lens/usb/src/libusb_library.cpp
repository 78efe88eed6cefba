// See libusb_library.h.
#include "libusb_library.h"

#include <cstdio>
#include <cstdlib>

#include "camhead/hal/shared_library.h"

namespace camhead::hal::lens::detail {
namespace {

struct LoadedLibusb {
  // Kept open for the life of the process: transfers and contexts may
  // outlive any one backend.
  SharedLibrary library{CAMHEAD_LIBUSB_SONAME, "libusb-1.0-0"};
  LibusbFunctions functions;

  LoadedLibusb() {
#define CAMHEAD_LIBUSB_RESOLVE(name) library.resolve("libusb_" #name, functions.name);
    CAMHEAD_LIBUSB_FUNCTIONS(CAMHEAD_LIBUSB_RESOLVE)
#undef CAMHEAD_LIBUSB_RESOLVE
  }
};

const LoadedLibusb &loaded() {
  static const LoadedLibusb instance;
  return instance;
}

} // namespace

const std::string &libusb_load_error() {
  return loaded().library.error();
}

const LibusbFunctions &libusb() {
  if (!loaded().library.ok()) {
    std::fprintf(stderr, "camhead: libusb called without checking: %s\n",
                 loaded().library.error().c_str());
    std::abort();
  }
  return loaded().functions;
}

} // namespace camhead::hal::lens::detail
