// The device libraries opened at run time (camhead/hal/shared_library.h):
// a missing library or symbol is an error that names it, and on a machine
// with the packages installed every function the backends call is found
// (a misspelt name or a library of another version fails here, not on a
// board).
#include <cstring>
#include <string>

#include "camhead/hal/shared_library.h"
#include "gpiod_library.h"
#include "libusb_library.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace camhead::hal {
namespace {

using testing::HasSubstr;

TEST(SharedLibrary, MissingLibraryNamesFileAndPackage) {
  SharedLibrary library("libcamhead-no-such-library.so.7", "camhead-no-such-package");
  EXPECT_FALSE(library.ok());
  EXPECT_THAT(library.error(), HasSubstr("libcamhead-no-such-library.so.7 (Debian package "
                                         "camhead-no-such-package) cannot be loaded: "));
  decltype(&std::strlen) function = &std::strlen;
  library.resolve("strlen", function);
  EXPECT_EQ(function, nullptr);
}

TEST(SharedLibrary, MissingSymbolNamesIt) {
  SharedLibrary library("libc.so.6", "libc6");
  ASSERT_TRUE(library.ok()) << library.error();
  decltype(&std::strlen) strlen_function = nullptr;
  library.resolve("strlen", strlen_function);
  ASSERT_NE(strlen_function, nullptr);
  EXPECT_EQ(strlen_function("camhead"), 7u);
  EXPECT_TRUE(library.ok());

  void (*absent)() = nullptr;
  library.resolve("camhead_no_such_function", absent);
  EXPECT_EQ(absent, nullptr);
  EXPECT_FALSE(library.ok());
  EXPECT_THAT(library.error(), HasSubstr("libc.so.6 (Debian package libc6) has no "
                                         "camhead_no_such_function"));
}

TEST(DeviceLibraries, LibusbHasEveryFunctionTheBackendCalls) {
  ASSERT_EQ(lens::detail::libusb_load_error(), "");
  const lens::detail::LibusbFunctions &usb = lens::detail::libusb();
#define CAMHEAD_EXPECT_FOUND(name) EXPECT_NE(usb.name, nullptr) << "libusb_" #name;
  CAMHEAD_LIBUSB_FUNCTIONS(CAMHEAD_EXPECT_FOUND)
#undef CAMHEAD_EXPECT_FOUND
  EXPECT_STREQ(usb.error_name(LIBUSB_ERROR_NO_DEVICE), "LIBUSB_ERROR_NO_DEVICE");
}

TEST(DeviceLibraries, LibgpiodHasEveryFunctionTheBackendCalls) {
  ASSERT_EQ(lens::gpio::detail::gpiod_load_error(), "");
  const lens::gpio::detail::GpiodFunctions &gpiod = lens::gpio::detail::gpiod();
#define CAMHEAD_EXPECT_FOUND(name) EXPECT_NE(gpiod.name, nullptr) << "gpiod_" #name;
  CAMHEAD_GPIOD_FUNCTIONS(CAMHEAD_EXPECT_FOUND)
#undef CAMHEAD_EXPECT_FOUND
  // No chip by this name on any machine: the call reaches the real library.
  EXPECT_EQ(gpiod.chip_open_lookup("camhead-no-such-chip"), nullptr);
}

} // namespace
} // namespace camhead::hal
