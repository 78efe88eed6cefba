// What open_v4l2_camera and open_v4l2_loopback_sink say when they cannot
// open: the device is named, with the reason, and nothing else is touched.
// The lab (tests/vm, vm.v4l2_*) opens real devices.
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <unistd.h>

#include "camhead/hal/camera/v4l2/v4l2_camera.h"
#include "camhead/hal/output/v4l2/v4l2_loopback_sink.h"
#include "camhead/hal/v4l2/device_file.h"

#include <gtest/gtest.h>

namespace camhead::hal {
namespace {

using camera::open_v4l2_camera;
using camera::V4l2CameraError;
using camera::V4l2CameraOptions;
using output::open_v4l2_loopback_sink;
using output::V4l2SinkError;

V4l2CameraOptions camera_options(std::string device) {
  V4l2CameraOptions options;
  options.device = std::move(device);
  options.width = 640;
  options.height = 480;
  options.fps = 25;
  return options;
}

template <class Error> std::string error_of(const std::function<void()> &open) {
  try {
    open();
  } catch (const Error &e) {
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return {};
}

std::string camera_error(const V4l2CameraOptions &options) {
  return error_of<V4l2CameraError>([&] { (void)open_v4l2_camera(options); });
}

std::string sink_error(const std::string &device, base::VideoFormat format, double fps = 25) {
  return error_of<V4l2SinkError>([&] { (void)open_v4l2_loopback_sink(device, format, fps); });
}

bool contains(const std::string &text, const std::string &part) {
  return text.find(part) != std::string::npos;
}

std::filesystem::path scratch(const std::string &name) {
  return std::filesystem::temp_directory_path() /
         ("camhead_v4l2_" + std::to_string(::getpid()) + "_" + name);
}

TEST(V4l2OpenErrors, NotAV4l2DeviceIsNamed) {
  const std::string camera = camera_error(camera_options("/dev/null"));
  EXPECT_TRUE(contains(camera, "/dev/null: not a V4L2 device")) << camera;
  const std::string sink = sink_error("/dev/null", {base::PixelFormat::yuyv, 640, 480});
  EXPECT_TRUE(contains(sink, "/dev/null: not a V4L2 device")) << sink;
}

TEST(V4l2OpenErrors, AMissingDeviceIsNamedWithTheReason) {
  const std::string missing = "/dev/v4l/by-id/usb-camhead-missing-video-index0";
  const std::string camera = camera_error(camera_options(missing));
  EXPECT_TRUE(contains(camera, missing + ": cannot open: No such file or directory")) << camera;
  const std::string sink =
      sink_error("/dev/video-camhead-missing", {base::PixelFormat::nv12, 64, 48});
  EXPECT_TRUE(contains(sink, "/dev/video-camhead-missing: cannot open")) << sink;
}

TEST(V4l2OpenErrors, ARegularFileIsRefusedAndLeftAlone) {
  const std::filesystem::path file = scratch("regular");
  std::ofstream(file) << "not a camera";
  const std::string camera = camera_error(camera_options(file.string()));
  EXPECT_TRUE(contains(camera, file.string() + ": is not a device node")) << camera;
  const std::string sink = sink_error(file.string(), {base::PixelFormat::yuyv, 64, 48});
  EXPECT_TRUE(contains(sink, "is not a device node")) << sink;
  EXPECT_EQ(std::filesystem::file_size(file), 12u); // not truncated, not written
  std::filesystem::remove(file);
}

TEST(V4l2OpenErrors, AFolderIsRefused) {
  const std::string camera = camera_error(camera_options("/dev"));
  EXPECT_TRUE(contains(camera, "/dev: cannot open: Is a directory")) << camera;
}

TEST(V4l2OpenErrors, OptionsAreCheckedBeforeTheDeviceIsOpened) {
  V4l2CameraOptions options = camera_options("/dev/video0");
  options.format = base::PixelFormat::xrgb8888;
  EXPECT_TRUE(contains(camera_error(options), "/dev/video0: format: xrgb8888 is a display"));
  options = camera_options("/dev/video0");
  options.width = 641;
  EXPECT_TRUE(contains(camera_error(options), "/dev/video0: format: yuyv needs an even width"));
  options = camera_options("/dev/video0");
  options.fps = -1;
  EXPECT_TRUE(contains(camera_error(options), "/dev/video0: fps:"));
  options = camera_options("/dev/video0");
  options.buffers = 1;
  EXPECT_TRUE(contains(camera_error(options), "/dev/video0: buffers: 1 is not 2 to 8"));
  EXPECT_TRUE(contains(camera_error(camera_options("")), "no device named"));
}

TEST(V4l2OpenErrors, SinkTakesYuyvAndNv12AtARate) {
  const std::string rgb = sink_error("/dev/video10", {base::PixelFormat::rgb24, 64, 48});
  EXPECT_TRUE(contains(rgb, "/dev/video10: format: rgb24 cannot go to a V4L2 loopback device"))
      << rgb;
  const std::string odd = sink_error("/dev/video10", {base::PixelFormat::nv12, 64, 47});
  EXPECT_TRUE(contains(odd, "/dev/video10: format: nv12 needs an even height")) << odd;
  const std::string rate = sink_error("/dev/video10", {base::PixelFormat::yuyv, 64, 48}, 0);
  EXPECT_TRUE(contains(rate, "/dev/video10: fps:")) << rate;
}

TEST(V4l2DeviceFile, GoneMeansTheDeviceNotTheRequest) {
  EXPECT_TRUE(v4l2::is_device_gone(ENODEV));
  EXPECT_TRUE(v4l2::is_device_gone(ENXIO));
  EXPECT_FALSE(v4l2::is_device_gone(EINVAL));
  EXPECT_FALSE(v4l2::is_device_gone(EAGAIN));
  EXPECT_EQ(v4l2::errno_text(ENOENT), "No such file or directory");
  EXPECT_EQ(v4l2::caps_text(0), "no video capture or output");
}

} // namespace
} // namespace camhead::hal
