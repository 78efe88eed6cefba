// The libcamera backend's pure parts (hal/camera/libcamera/src/stream_settings.h):
// formats, the words of its errors, option checks, colour and plane layout.
#include "stream_settings.h"

#include <gtest/gtest.h>

namespace camhead::hal::camera::libcamera_settings {
namespace {

using base::PixelFormat;

TEST(LibcameraFormats, RgbNamesFollowLibcamerasLittleEndianWords) {
  // libcamera's RGB888 is B, G, R in memory: camhead's bgr24.
  EXPECT_EQ(libcamera_fourcc(PixelFormat::bgr24), fourcc('R', 'G', '2', '4'));
  EXPECT_EQ(libcamera_fourcc(PixelFormat::rgb24), fourcc('B', 'G', '2', '4'));
  EXPECT_EQ(camhead_format(kRgb888), PixelFormat::bgr24);
  EXPECT_EQ(camhead_format(kBgr888), PixelFormat::rgb24);
  EXPECT_EQ(libcamera_format_name(kRgb888), "RGB888");
  EXPECT_EQ(libcamera_format_name(kBgr888), "BGR888");
}

TEST(LibcameraFormats, YuvFormatsMapOneToOne) {
  for (const PixelFormat format : {PixelFormat::yuyv, PixelFormat::nv12}) {
    const std::optional<std::uint32_t> code = libcamera_fourcc(format);
    ASSERT_TRUE(code);
    EXPECT_EQ(camhead_format(*code), format);
  }
  EXPECT_EQ(libcamera_format_name(kYuyv), "YUYV");
  EXPECT_EQ(libcamera_format_name(kNv12), "NV12");
}

TEST(LibcameraFormats, DisplayAndUnknownFormatsHaveNoCounterpart) {
  EXPECT_FALSE(libcamera_fourcc(PixelFormat::xrgb8888));
  EXPECT_FALSE(camhead_format(fourcc('M', 'J', 'P', 'G')));
  EXPECT_EQ(libcamera_format_name(fourcc('M', 'J', 'P', 'G')), "MJPG");
  EXPECT_EQ(libcamera_format_name(fourcc('R', '8', ' ', ' ')), "R8");
  EXPECT_EQ(libcamera_format_name(0x01020304), "0x01020304");
}

TEST(LibcameraMessages, ShapesNameBothFormats) {
  EXPECT_EQ(describe({kRgb888, 636, 480}), "636x480 RGB888 (camhead bgr24)");
  EXPECT_EQ(describe({fourcc('M', 'J', 'P', 'G'), 1280, 720}), "1280x720 MJPG (no camhead format)");
}

TEST(LibcameraMessages, CamerasAreNamedAsCamListsThem) {
  EXPECT_EQ(camera_label("platform/vimc.0 Sensor B", "Sensor B"),
            "'Sensor B' (platform/vimc.0 Sensor B)");
  EXPECT_EQ(camera_label("usb-0000:00:14.0-1", ""), "(usb-0000:00:14.0-1)");
}

TEST(LibcameraMessages, AnAdjustedSizeNamesTheCameraAndBothConfigurations) {
  const std::string message = adjusted_message("'Sensor B' (platform/vimc.0 Sensor B)",
                                               {kRgb888, 640, 480}, {kRgb888, 636, 480});
  EXPECT_EQ(message, "libcamera camera 'Sensor B' (platform/vimc.0 Sensor B): asked 640x480 "
                     "RGB888 (camhead bgr24), the camera gives 636x480 RGB888 (camhead bgr24); "
                     "choose a size it gives unchanged (636x480 here)");
}

TEST(LibcameraMessages, AnAdjustedFormatSaysToChooseAnother) {
  const std::string message = adjusted_message("(cam)", {kYuyv, 640, 480}, {kBgr888, 636, 480});
  EXPECT_NE(message.find("asked 640x480 YUYV (camhead yuyv)"), std::string::npos) << message;
  EXPECT_NE(message.find("gives 636x480 BGR888 (camhead rgb24)"), std::string::npos) << message;
  EXPECT_NE(message.find("choose a format the camera offers and choose a size"), std::string::npos)
      << message;
}

TEST(LibcameraOptions, BadOptionsAreNamed) {
  LibcameraCameraOptions options{"", PixelFormat::yuyv, 640, 480, 4};
  EXPECT_EQ(check_options(options), "");
  options.format = PixelFormat::xrgb8888;
  EXPECT_NE(check_options(options).find("xrgb8888 is a display format"), std::string::npos);
  options.format = PixelFormat::yuyv;
  options.width = 641;
  EXPECT_NE(check_options(options).find("even width"), std::string::npos);
  options.width = 0;
  EXPECT_NE(check_options(options).find("is empty"), std::string::npos);
  options.width = 640;
  options.buffers = 1;
  EXPECT_EQ(check_options(options), "buffers: 1 is not 2 to 8");
  options.buffers = 9;
  EXPECT_EQ(check_options(options), "buffers: 9 is not 2 to 8");
}

TEST(LibcameraColour, UnsaidColourFollowsTheHeight) {
  base::VideoFormat sd{PixelFormat::yuyv, 720, 576};
  apply_colour(sd, std::nullopt);
  EXPECT_EQ(sd.matrix, base::ColorMatrix::bt601);
  EXPECT_EQ(sd.range, base::ColorRange::limited);
  base::VideoFormat hd{PixelFormat::nv12, 1920, 1080};
  apply_colour(hd, StreamColour{YcbcrEncoding::none, true});
  EXPECT_EQ(hd.matrix, base::ColorMatrix::bt709);
  EXPECT_EQ(hd.range, base::ColorRange::limited);
}

TEST(LibcameraColour, SaidColourIsTaken) {
  base::VideoFormat format{PixelFormat::nv12, 1920, 1080};
  apply_colour(format, StreamColour{YcbcrEncoding::rec601, true}); // sYCC, a JPEG-like stream
  EXPECT_EQ(format.matrix, base::ColorMatrix::bt601);
  EXPECT_EQ(format.range, base::ColorRange::full);
  apply_colour(format, StreamColour{YcbcrEncoding::rec2020, false});
  EXPECT_EQ(format.matrix, base::ColorMatrix::bt709);
  EXPECT_EQ(format.range, base::ColorRange::limited);
}

TEST(LibcameraPlanes, OnePlaneFramesMapFromTheirOffset) {
  const base::VideoFormat format{PixelFormat::bgr24, 480, 360, 1440};
  std::string error;
  const std::optional<FrameRegion> region = frame_region({{7, 0, 1440 * 360}}, format, error);
  ASSERT_TRUE(region) << error;
  EXPECT_EQ(region->fd, 7);
  EXPECT_EQ(region->map_length, 1440u * 360);
  EXPECT_EQ(region->frame_offset, 0u);
  EXPECT_FALSE(frame_region({{7, 0, 1440 * 359}}, format, error));
  EXPECT_EQ(error, "the buffer holds 516960 bytes, a frame needs 518400");
}

TEST(LibcameraPlanes, Nv12ChromaMustFollowTheLuma) {
  const base::VideoFormat format{PixelFormat::nv12, 64, 48, 64};
  std::string error;
  const std::optional<FrameRegion> region =
      frame_region({{3, 0, 64 * 48}, {3, 64 * 48, 64 * 24}}, format, error);
  ASSERT_TRUE(region) << error;
  EXPECT_EQ(region->map_length, 64u * 72);
  // NV12M: chroma in its own dmabuf.
  EXPECT_FALSE(frame_region({{3, 0, 64 * 48}, {4, 0, 64 * 24}}, format, error));
  EXPECT_NE(error.find("not right after the luma"), std::string::npos) << error;
  EXPECT_FALSE(frame_region({{3, 0, 64 * 48}}, format, error));
  EXPECT_EQ(error, "the buffer has 1 planes, not 2");
}

} // namespace
} // namespace camhead::hal::camera::libcamera_settings
