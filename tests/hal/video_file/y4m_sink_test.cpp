// The Y4M sink puts its file in place only at close(), refuses targets a
// rename must not replace (device nodes, FIFOs, folders) and folders it
// cannot write at open, and takes strided frames.
#include <csignal>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "camhead/hal/camera/file/file_camera.h"
#include "camhead/hal/output/file/file_sink.h"
#include "video_test_files.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using base::PixelFormat;
using hal::output::FileSinkError;

const base::VideoFormat kFormat = test::make_format(PixelFormat::yuyv, 8, 2);

std::string open_error(const std::filesystem::path &path, base::VideoFormat format = kFormat,
                       double fps = 25) {
  try {
    auto sink = hal::output::open_y4m_sink(path, format, fps);
  } catch (const FileSinkError &e) {
    return e.what();
  }
  return "opened";
}

void submit_one(hal::output::FrameSink &sink, int seed) {
  const auto frame = test::generated_frame(sink.format(), seed);
  ASSERT_TRUE(sink.submit(frame, 0)) << sink.status().detail;
}

TEST(Y4mSink, TheFinalFileAppearsOnlyAtClose) {
  const test::ScratchDir dir;
  const auto path = dir / "out.y4m";
  const auto partial = dir / "out.y4m.partial";
  auto sink = hal::output::open_y4m_sink(path, kFormat, 25);
  EXPECT_EQ(sink->name(), "file " + path.string());
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(std::filesystem::exists(partial));
  submit_one(*sink, 0);
  submit_one(*sink, 1);
  EXPECT_FALSE(std::filesystem::exists(path));
  ASSERT_TRUE(sink->close()) << sink->status().detail;
  EXPECT_TRUE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(partial));
  const auto status = sink->status();
  EXPECT_EQ(status.frames, 2u);
  EXPECT_EQ(status.errors, 0u);
  EXPECT_FALSE(status.connected);
  EXPECT_EQ(std::filesystem::file_size(path),
            std::string("YUV4MPEG2 W8 H2 F25:1 Ip A1:1 C422 XCOLORRANGE=LIMITED\n").size() +
                2 * (6 + 32));
}

TEST(Y4mSink, AnOldFileStaysWholeUntilClose) {
  const test::ScratchDir dir;
  const auto path = dir / "out.y4m";
  test::write_text(path, "the previous take");
  {
    auto sink = hal::output::open_y4m_sink(path, kFormat, 25);
    submit_one(*sink, 0);
    EXPECT_EQ(test::read_text(path), "the previous take");
    // Destroyed without close(): the take is abandoned, the old file kept.
  }
  EXPECT_EQ(test::read_text(path), "the previous take");
  EXPECT_FALSE(std::filesystem::exists(dir / "out.y4m.partial"));

  auto sink = hal::output::open_y4m_sink(path, kFormat, 25);
  submit_one(*sink, 0);
  ASSERT_TRUE(sink->close());
  EXPECT_EQ(test::read_text(path).rfind("YUV4MPEG2 ", 0), 0u);
}

TEST(Y4mSink, RefusesTargetsThatAreNotRegularFiles) {
  EXPECT_EQ(open_error("/dev/null"),
            "/dev/null: exists and is a device node, not a regular file: refusing to replace it");
  EXPECT_FALSE(std::filesystem::exists("/dev/null.partial"));

  const test::ScratchDir dir;
  std::filesystem::create_directory(dir / "folder.y4m");
  EXPECT_EQ(open_error(dir / "folder.y4m"),
            (dir / "folder.y4m").string() +
                ": exists and is a folder, not a regular file: refusing to replace it");
  ASSERT_EQ(::mkfifo((dir / "fifo.y4m").c_str(), 0600), 0);
  EXPECT_EQ(open_error(dir / "fifo.y4m"),
            (dir / "fifo.y4m").string() +
                ": exists and is a FIFO, not a regular file: refusing to replace it");
  std::filesystem::create_symlink("/dev/null", dir / "link.y4m");
  EXPECT_NE(open_error(dir / "link.y4m").find("is a device node"), std::string::npos);
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "link.y4m"));
  EXPECT_EQ(open_error("-"), "-: writing to standard output is not supported; give a file name");
}

TEST(Y4mSink, ALinkIsFollowedAndKept) {
  const test::ScratchDir dir;
  std::filesystem::create_directory(dir / "library");
  test::write_text(dir / "library" / "take.y4m", "old");
  std::filesystem::create_symlink(dir / "library" / "take.y4m", dir / "link.y4m");
  auto sink = hal::output::open_y4m_sink(dir / "link.y4m", kFormat, 25);
  EXPECT_TRUE(std::filesystem::exists(dir / "library" / "take.y4m.partial"));
  submit_one(*sink, 0);
  ASSERT_TRUE(sink->close()) << sink->status().detail;
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "link.y4m"));
  EXPECT_EQ(test::read_text(dir / "link.y4m").rfind("YUV4MPEG2 ", 0), 0u);
  EXPECT_FALSE(std::filesystem::exists(dir / "library" / "take.y4m.partial"));
}

TEST(Y4mSink, AMissingFolderFailsAtOpen) {
  const test::ScratchDir dir;
  const auto missing = dir / "no_such_folder" / "out.y4m";
  EXPECT_EQ(open_error(missing), missing.string() + ": cannot create " + missing.string() +
                                     ".partial: No such file or directory");
}

TEST(Y4mSink, AReadOnlyFolderFailsAtOpen) {
  if (::geteuid() == 0)
    GTEST_SKIP() << "running as root, which may write into a read-only folder";
  const test::ScratchDir dir;
  std::filesystem::create_directory(dir / "ro");
  std::filesystem::permissions(dir / "ro", std::filesystem::perms::owner_read |
                                               std::filesystem::perms::owner_exec);
  EXPECT_NE(open_error(dir / "ro" / "out.y4m").find("Permission denied"), std::string::npos);
  std::filesystem::permissions(dir / "ro", std::filesystem::perms::owner_all);
}

TEST(Y4mSink, RefusesFormatsAndRatesItCannotWrite) {
  const test::ScratchDir dir;
  const auto path = dir / "out.y4m";
  EXPECT_EQ(open_error(path, test::make_format(PixelFormat::rgb24, 8, 2)),
            path.string() + ": format: rgb24 cannot be written as Y4M; use yuyv or nv12");
  EXPECT_EQ(open_error(path, test::make_format(PixelFormat::yuyv, 7, 2)),
            path.string() + ": format: yuyv needs an even width, not 7");
  EXPECT_EQ(open_error(path, kFormat, 0).rfind(path.string() + ": fps: ", 0), 0u);
  EXPECT_EQ(open_error("", kFormat), "Y4M sink: the path is empty");
  EXPECT_FALSE(std::filesystem::exists(dir / "out.y4m.partial"));
}

TEST(Y4mSink, MisuseIsAStatusNotAThrow) {
  const test::ScratchDir dir;
  auto sink = hal::output::open_y4m_sink(dir / "out.y4m", kFormat, 25);
  const auto frame = test::generated_frame(kFormat, 0);
  EXPECT_FALSE(sink->submit(std::span(frame).first(frame.size() - 2), 0));
  EXPECT_NE(sink->status().detail.find("a frame of 30 bytes, not the 32 of "), std::string::npos)
      << sink->status().detail;
  submit_one(*sink, 0);
  ASSERT_TRUE(sink->close());
  EXPECT_FALSE(sink->submit(frame, 0));
  EXPECT_FALSE(sink->close());
  EXPECT_EQ(sink->status().errors, 3u);
  EXPECT_EQ(sink->status().frames, 1u);
  EXPECT_EQ(test::read_text(dir / "out.y4m")
                .rfind("YUV4MPEG2 W8 H2 F25:1 Ip A1:1 C422 XCOLORRANGE=LIMITED\nFRAME\n", 0),
            0u);
}

// A run stopped before its first frame (Ctrl-C while it starts) leaves no
// file that no player opens, and keeps the take that was there.
TEST(Y4mSink, WithoutAFrameTheOldFileIsKept) {
  const test::ScratchDir dir;
  test::write_text(dir / "take.y4m", "the take of yesterday");
  auto sink = hal::output::open_y4m_sink(dir / "take.y4m", kFormat, 25);
  EXPECT_FALSE(sink->close());
  EXPECT_EQ(sink->status().detail, "file " + (dir / "take.y4m").string() +
                                       ": not written: no frame reached it (an earlier file "
                                       "of that name is kept)");
  EXPECT_EQ(test::read_text(dir / "take.y4m"), "the take of yesterday");
  EXPECT_FALSE(std::filesystem::exists(dir / "take.y4m.partial"));
}

TEST(Y4mSink, AFailedWriteIsCutOffAndTheFileStaysWhole) {
  const test::ScratchDir dir;
  const std::string header = "YUV4MPEG2 W8 H2 F25:1 Ip A1:1 C422 XCOLORRANGE=LIMITED\n";
  const rlim_t record = 6 + 32;
  auto sink = hal::output::open_y4m_sink(dir / "out.y4m", kFormat, 25);
  // A disk that fills up half-way through the second frame (EFBIG rather
  // than ENOSPC, and the signal that comes with it ignored).
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = old;
  small.rlim_cur = header.size() + record + record / 2;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  submit_one(*sink, 0);
  const auto frame = test::generated_frame(kFormat, 1);
  for (int i = 0; i < 2; ++i)
    EXPECT_FALSE(sink->submit(frame, 0));
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &old), 0);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(sink->status().detail.find("File too large"), std::string::npos)
      << sink->status().detail;
  submit_one(*sink, 2); // room again: the stream goes on
  ASSERT_TRUE(sink->close()) << sink->status().detail;
  EXPECT_EQ(sink->status().frames, 2u);
  EXPECT_EQ(sink->status().errors, 2u);

  hal::camera::FileCameraOptions options;
  options.path = dir / "out.y4m";
  options.realtime = false;
  auto camera = hal::camera::open_file_camera(options);
  EXPECT_EQ(test::read_all(*camera),
            (std::vector<std::vector<std::uint8_t>>{test::generated_frame(kFormat, 0),
                                                    test::generated_frame(kFormat, 2)}));
  EXPECT_EQ(camera->status().errors, 0u) << camera->status().detail;
}

TEST(Y4mSink, TakesStridedFramesAndWritesThemPacked) {
  const test::ScratchDir dir;
  base::VideoFormat strided = test::make_format(PixelFormat::nv12, 8, 4);
  strided.stride = 12;
  const auto frame = test::generated_frame(strided, 3);
  auto sink = hal::output::open_y4m_sink(dir / "out.y4m", strided, 25);
  test::write_all(*sink, {frame});

  hal::camera::FileCameraOptions options;
  options.path = dir / "out.y4m";
  options.realtime = false;
  auto camera = hal::camera::open_file_camera(options);
  const auto read = test::read_all(*camera);
  ASSERT_EQ(read.size(), 1u);
  ASSERT_EQ(read[0].size(), 8u * 6);
  for (std::size_t row = 0; row < 6; ++row) // 4 luma rows, 2 chroma rows
    for (std::size_t x = 0; x < 8; ++x)
      EXPECT_EQ(read[0][row * 8 + x], frame[row * 12 + x]) << "row " << row << " x " << x;
}

} // namespace
} // namespace camhead
