// ffmpeg, when installed, decodes the sink's Y4M to the very bytes the sink
// was given: the files are usable outside camhead, not just by our reader.
#include <cstdlib>
#include <string>
#include <vector>

#include "camhead/hal/output/file/file_sink.h"
#include "video_test_files.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

void expect_ffmpeg_decodes(const base::VideoFormat &format, const char *ffmpeg_pix_fmt) {
  if (std::system("command -v ffmpeg >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "ffmpeg is not installed";
  const test::ScratchDir dir;
  const std::vector<std::vector<std::uint8_t>> frames = {test::generated_frame(format, 0),
                                                         test::generated_frame(format, 1)};
  auto sink = hal::output::open_y4m_sink(dir / "take.y4m", format, 25);
  test::write_all(*sink, frames);
  const std::string command = "ffmpeg -nostdin -v error -y -i '" + (dir / "take.y4m").string() +
                              "' -f rawvideo -pix_fmt " + ffmpeg_pix_fmt + " '" +
                              (dir / "raw").string() + "'";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  std::string expected;
  for (const auto &frame : frames)
    expected.append(frame.begin(), frame.end());
  EXPECT_EQ(test::read_text(dir / "raw"), expected);
}

TEST(FfmpegDecode, YuyvY4m) {
  expect_ffmpeg_decodes(test::make_format(base::PixelFormat::yuyv, 32, 16), "yuyv422");
}

TEST(FfmpegDecode, Nv12Y4m) {
  expect_ffmpeg_decodes(test::make_format(base::PixelFormat::nv12, 32, 16), "nv12");
}

} // namespace
} // namespace camhead
