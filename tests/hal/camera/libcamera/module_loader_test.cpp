// Opening the libcamera backend module at run time
// (hal/camera/libcamera/src/libcamera_loader.cpp): a missing module is a
// clear error, and where libcamera-dev was installed at build time the built
// module loads and answers. This machine has no camera; the hardware lab
// (tests/vm, vm.libcamera_*) captures from vimc.
#include <cstdlib>
#include <string>

#include <dlfcn.h>

#include "camhead/hal/camera/libcamera/libcamera_camera.h"
#include "module_abi.h"

#include <gtest/gtest.h>

namespace camhead::hal::camera {
namespace {

// Points the loader at `path` for one test.
class ModulePath {
public:
  explicit ModulePath(const char *path) { ::setenv("CAMHEAD_LIBCAMERA_MODULE", path, 1); }
  ~ModulePath() { ::unsetenv("CAMHEAD_LIBCAMERA_MODULE"); }
  ModulePath(const ModulePath &) = delete;
  ModulePath &operator=(const ModulePath &) = delete;
};

const char *built_module() {
#ifdef CAMHEAD_TEST_LIBCAMERA_MODULE
  return CAMHEAD_TEST_LIBCAMERA_MODULE;
#else
  return nullptr;
#endif
}

TEST(LibcameraModule, AMissingModuleNamesItselfAndThePackage) {
  const ModulePath path("/nonexistent/libcamhead_libcamera.so");
  try {
    (void)open_libcamera_camera({"", base::PixelFormat::yuyv, 640, 480, 4});
    FAIL() << "opened a camera without a module";
  } catch (const LibcameraCameraError &e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("/nonexistent/libcamhead_libcamera.so"), std::string::npos) << message;
    EXPECT_NE(message.find("libcamera0.0.3"), std::string::npos) << message;
  }
  EXPECT_THROW((void)list_libcamera_cameras(), LibcameraCameraError);
  EXPECT_STREQ(libcamera_module_name(), "libcamhead_libcamera.so");
}

TEST(LibcameraModule, WithoutAModuleTheErrorSaysWhereItLooked) {
  // This test program's folder has no module beside it, nor a lib/camhead.
  ::unsetenv("CAMHEAD_LIBCAMERA_MODULE");
  try {
    (void)list_libcamera_cameras();
    FAIL() << "listed cameras without a module";
  } catch (const LibcameraCameraError &e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("libcamhead_libcamera.so is not in "), std::string::npos) << message;
    EXPECT_NE(message.find("lib/camhead, the library path"), std::string::npos) << message;
    EXPECT_NE(message.find("libcamera-dev"), std::string::npos) << message;
    EXPECT_NE(message.find("libcamera0.0.3"), std::string::npos) << message;
  }
}

TEST(LibcameraModule, TheFactoryRefusesAnotherAbi) {
  if (built_module() == nullptr)
    GTEST_SKIP() << "libcamera-dev was not installed at build time: no module to load";
  void *handle = ::dlopen(built_module(), RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(handle, nullptr) << ::dlerror();
  auto factory = reinterpret_cast<libcamera_module::Factory>(
      ::dlsym(handle, libcamera_module::kFactorySymbol));
  ASSERT_NE(factory, nullptr);
  EXPECT_EQ(factory(libcamera_module::kAbiVersion + 1), nullptr);
  EXPECT_NE(factory(libcamera_module::kAbiVersion), nullptr);
  // Left open, as the loader leaves it: libcamera's statics stay valid.
}

TEST(LibcameraModule, TheBuiltModuleListsAndRefusesClearly) {
  if (built_module() == nullptr)
    GTEST_SKIP() << "libcamera-dev was not installed at build time: no module to load";
  const ModulePath path(built_module());
  // No camera here; listing must still work.
  EXPECT_NO_THROW((void)list_libcamera_cameras());
  try {
    (void)open_libcamera_camera({"no such camera", base::PixelFormat::yuyv, 640, 480, 4});
    FAIL() << "opened a camera that does not exist";
  } catch (const LibcameraCameraError &e) {
    EXPECT_NE(std::string(e.what()).find("no camera no such camera"), std::string::npos)
        << e.what();
  }
  try {
    (void)open_libcamera_camera({"", base::PixelFormat::yuyv, 640, 480, 1});
    FAIL() << "took a buffer count of 1";
  } catch (const LibcameraCameraError &e) {
    EXPECT_NE(std::string(e.what()).find("buffers: 1 is not 2 to 8"), std::string::npos)
        << e.what();
  }
}

} // namespace
} // namespace camhead::hal::camera
