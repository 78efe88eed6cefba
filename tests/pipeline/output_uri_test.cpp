// `camhead run --output URI`: every form it takes, and every mistake named
// with the URI before anything is opened.
#include <string>

#include "run/output_uri.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

std::string error_of(const std::string &uri) {
  try {
    (void)parse_output_uri(uri);
  } catch (const OutputError &e) {
    return e.what();
  }
  return "(no error)";
}

TEST(OutputUri, EveryForm) {
  OutputSpec s = parse_output_uri("v4l2:/dev/video10");
  EXPECT_EQ(s.kind, OutputKind::v4l2);
  EXPECT_EQ(s.target, "/dev/video10");
  EXPECT_EQ(s.format, base::PixelFormat::yuyv);
  s = parse_output_uri("v4l2:/dev/video10?format=nv12");
  EXPECT_EQ(s.target, "/dev/video10");
  EXPECT_EQ(s.format, base::PixelFormat::nv12);
  s = parse_output_uri("file:take.y4m?format=nv12");
  EXPECT_EQ(s.kind, OutputKind::y4m);
  EXPECT_EQ(s.target, "take.y4m");
  EXPECT_EQ(s.format, base::PixelFormat::nv12);
  s = parse_output_uri("file:frames/%05d.png");
  EXPECT_EQ(s.kind, OutputKind::png);
  EXPECT_EQ(s.format, base::PixelFormat::rgb24);
  s = parse_output_uri("drm:card0:HDMI-A-1?mode=1920x1080@50");
  EXPECT_EQ(s.kind, OutputKind::drm);
  EXPECT_EQ(s.target, "card0");
  EXPECT_EQ(s.connector, "HDMI-A-1");
  EXPECT_EQ(s.mode, "1920x1080@50");
  EXPECT_EQ(s.format, base::PixelFormat::xrgb8888);
  s = parse_output_uri("drm:bochs-drm");
  EXPECT_EQ(s.target, "bochs-drm");
  EXPECT_TRUE(s.connector.empty() && s.mode.empty());
  EXPECT_EQ(parse_output_uri("null").kind, OutputKind::null);
}

TEST(OutputUri, MistakesAreNamedWithTheUri) {
  EXPECT_EQ(error_of("webcam"),
            "webcam: not an output URI (v4l2:/dev/videoN, drm:CARD[:CONNECTOR], "
            "file:PATH.y4m, file:DIR/%05d.png or null)");
  EXPECT_EQ(error_of("rtmp://host/live"),
            "rtmp://host/live: unknown output \"rtmp\" (v4l2:/dev/videoN, drm:CARD[:CONNECTOR], "
            "file:PATH.y4m, file:DIR/%05d.png or null)");
  EXPECT_EQ(error_of("file:take.mp4"), "file:take.mp4: a file output is PATH.y4m or DIR/%05d.png");
  EXPECT_EQ(error_of("file:frames/still.png"),
            "file:frames/still.png: a PNG sequence needs a frame number in its name, e.g. "
            "file:frames/%05d.png");
  EXPECT_EQ(error_of("v4l2:/dev/video10?format=mjpeg"),
            "v4l2:/dev/video10?format=mjpeg: format: \"mjpeg\" is not yuyv or nv12");
  EXPECT_EQ(error_of("v4l2:/dev/video10?fps=30"),
            "v4l2:/dev/video10?fps=30: unknown option \"fps=30\" (only format=yuyv|nv12)");
  EXPECT_EQ(error_of("v4l2:?format=nv12"), "v4l2:?format=nv12: names no device or file");
  EXPECT_EQ(error_of("drm:card0:"),
            "drm:card0:: connector: empty (drm:CARD:CONNECTOR, e.g. drm:card0:HDMI-A-1)");
  EXPECT_EQ(error_of("drm:card0?rate=50"),
            "drm:card0?rate=50: unknown option \"rate=50\" (only mode=WxH or mode=WxH@Hz)");
  EXPECT_EQ(error_of("v4l2:"), "v4l2:: not an output URI (v4l2:/dev/videoN, drm:CARD[:CONNECTOR], "
                               "file:PATH.y4m, file:DIR/%05d.png or null)");
}

} // namespace
} // namespace camhead::pipeline
