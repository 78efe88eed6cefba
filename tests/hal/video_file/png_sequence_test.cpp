// PNG sequences: pixel-exact through the sink and the camera, by pattern and
// by folder; numbering from 0 or 1; sizes checked from the header before
// decoding; damaged frames refused before stb_image; the sink's pattern and
// format checks.
#include <string>
#include <vector>

#include "camhead/hal/camera/file/file_camera.h"
#include "camhead/hal/output/file/file_sink.h"
#include "camhead/hal/video_file/png_frame.h"
#include "png_chunks.h"
#include "video_test_files.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using base::PixelFormat;
using hal::camera::CapturedFrame;
using hal::camera::CaptureResult;
using hal::camera::FileCameraError;
using hal::camera::FileCameraOptions;

std::vector<std::vector<std::uint8_t>> frames_of(const base::VideoFormat &format, int count) {
  std::vector<std::vector<std::uint8_t>> frames;
  for (int i = 0; i < count; ++i)
    frames.push_back(test::generated_frame(format, i));
  return frames;
}

void write_sequence(const std::string &pattern, const base::VideoFormat &format, int count) {
  auto sink = hal::output::open_png_sequence_sink(pattern, format);
  test::write_all(*sink, frames_of(format, count));
}

std::unique_ptr<hal::camera::CameraSource> open(const std::filesystem::path &path,
                                                bool loop = false) {
  FileCameraOptions options;
  options.path = path;
  options.loop = loop;
  options.realtime = false;
  return hal::camera::open_file_camera(options);
}

std::string open_error(const std::filesystem::path &path) {
  try {
    auto camera = open(path);
  } catch (const FileCameraError &e) {
    return e.what();
  }
  return "opened";
}

// A real PNG whose header claims another width: stb reads the size from the
// header and does not check its CRC, so this tests the size check alone.
// A whole PNG, 4 rows of `width` pixels of noise (which does not compress,
// so its data can hold what its header states).
std::string png_of_width(int width) {
  std::vector<std::uint8_t> png;
  std::vector<std::uint8_t> rgb(std::size_t(width) * 4 * 3);
  std::uint32_t state = 1;
  for (std::uint8_t &b : rgb)
    b = std::uint8_t((state = state * 1664525u + 1013904223u) >> 24);
  EXPECT_TRUE(hal::video_file::encode_png_rgb(rgb, width, 4, std::size_t(width) * 3, png));
  return {png.begin(), png.end()};
}

TEST(PngSequence, RoundTripsPixelExactByPatternAndByFolder) {
  const test::ScratchDir dir;
  const auto format = test::make_format(PixelFormat::rgb24, 13, 7);
  // The folder does not exist yet: the sink creates it.
  const std::string pattern = (dir / "seq" / "%05d.png").string();
  write_sequence(pattern, format, 4);
  for (const char *name : {"00000.png", "00001.png", "00002.png", "00003.png"})
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "seq" / name)) << name;
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir / "seq"),
                          std::filesystem::directory_iterator()),
            4)
      << "no partial files left behind";

  for (const std::filesystem::path &source : {std::filesystem::path(pattern), dir / "seq"}) {
    auto camera = open(source);
    EXPECT_EQ(camera->format(), format) << source;
    EXPECT_EQ(camera->frame_interval_ns(), 40'000'000) << "25 fps for a sequence";
    EXPECT_EQ(test::read_all(*camera), frames_of(format, 4)) << source;
    CapturedFrame frame;
    EXPECT_EQ(camera->wait_frame(std::chrono::milliseconds(0), frame), CaptureResult::ended);
    EXPECT_EQ(camera->status().errors, 0u);
  }
}

TEST(PngSequence, NumberingMayStartAtOne) {
  const test::ScratchDir dir;
  const auto format = test::make_format(PixelFormat::rgb24, 4, 3);
  write_sequence((dir / "%03d.png").string(), format, 3);
  for (int i = 2; i >= 0; --i)
    std::filesystem::rename(dir / ("00" + std::to_string(i) + ".png"),
                            dir / ("00" + std::to_string(i + 1) + ".png"));
  auto camera = open(dir / "%03d.png");
  EXPECT_EQ(test::read_all(*camera), frames_of(format, 3));

  EXPECT_EQ(open_error(dir / "x%d.png"), (dir / "x%d.png").string() + ": frames: neither " +
                                             (dir / "x0.png").string() + " nor " +
                                             (dir / "x1.png").string() + " exists");
  EXPECT_EQ(open_error(dir / "%d_%d.png").find(": pattern: needs exactly one"),
            (dir / "%d_%d.png").string().size());
}

TEST(PngSequence, AStillFrameLoops) {
  const test::ScratchDir dir;
  const auto format = test::make_format(PixelFormat::rgb24, 4, 3);
  write_sequence((dir / "%d.png").string(), format, 1);
  auto camera = open(dir / "0.png", true);
  const auto frames = test::read_all(*camera, 3);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2], test::generated_frame(format, 0));
}

TEST(PngSequence, SizesAreCheckedFromTheHeaderBeforeDecoding) {
  const test::ScratchDir dir;
  test::write_text(dir / "huge.png", png_of_width(20000));
  EXPECT_EQ(open_error(dir / "huge.png"),
            (dir / "huge.png").string() + ": PNG header: size 20000x4 is over 16384 pixels a side");

  // A later frame that claims another size fails the take before it is
  // decoded, naming the file.
  const auto format = test::make_format(PixelFormat::rgb24, 4, 4);
  write_sequence((dir / "seq" / "%02d.png").string(), format, 2);
  test::write_text(dir / "seq" / "02.png", png_of_width(20000));
  auto camera = open(dir / "seq" / "%02d.png");
  EXPECT_EQ(test::read_all(*camera).size(), 2u);
  EXPECT_FALSE(camera->status().connected);
  EXPECT_EQ(camera->status().errors, 1u);
  EXPECT_EQ(camera->status().detail, (dir / "seq" / "02.png").string() +
                                         ":frame 2: size: 20000x4 differs from the first "
                                         "frame's 4x4");
}

TEST(PngSequence, AFrameThatIsNotAPngFailsTheTake) {
  const test::ScratchDir dir;
  const auto format = test::make_format(PixelFormat::rgb24, 4, 4);
  write_sequence((dir / "%d.png").string(), format, 1);
  test::write_text(dir / "1.png", "not a png at all");
  auto camera = open(dir.path());
  EXPECT_EQ(test::read_all(*camera).size(), 1u);
  EXPECT_EQ(camera->status().detail.rfind((dir / "1.png").string() + ":frame 1: PNG: ", 0), 0u)
      << camera->status().detail;
}

// The file camera decodes with the renderer's PNG reader (base/png_reader.h,
// libpng). What the fuzzers found against stb_image, which trusted the chunk
// structure (chunks cut short, where stb reallocated to the length claimed:
// 1.3 GB for 41 bytes; an empty IDAT it copied from a null pointer), is
// refused, most already as the header is read (the chunks are walked
// first); so is image data that inflates far past its header's image. The findings' CRCs are made
// right first, so that libpng meets what is really wrong with them, not a CRC.
TEST(PngSequence, DamagedFramesAreRefused) {
  const auto decode_error = [](const std::string &png) {
    const std::vector<std::uint8_t> bytes(png.begin(), png.end());
    std::string error;
    const auto size = hal::video_file::png_size(bytes, error);
    if (!size)
      return "size: " + error;
    std::vector<std::uint8_t> rgb(std::size_t(size->width) * std::size_t(size->height) * 3);
    return hal::video_file::decode_png_rgb(bytes, *size, rgb, error) ? std::string("decoded")
                                                                     : error;
  };
  const auto finding = [](const char *name) {
    return test::with_crcs_fixed(
        test::read_text(std::filesystem::path(CAMHEAD_SOURCE_DIR) / "tests/assets/fuzz" / name));
  };
  for (const char *name : {"png_inflate_oom_1.png", "png_inflate_oom_2.png",
                           "png_inflate_oom_1_min.png", "png_inflate_oom_2_min.png"})
    EXPECT_EQ(decode_error(finding(name)).rfind("size: PNG: not a readable PNG: the file ends ", 0),
              0u)
        << name << ": " << decode_error(finding(name));
  // libpng allocates an sPLT chunk at its claimed length before reading it:
  // the chunk walk refuses it first, CRC right or not.
  const std::string splt = test::read_text(std::filesystem::path(CAMHEAD_SOURCE_DIR) /
                                           "tests/assets/fuzz/png_splt_oom.png");
  for (const std::string &png : {splt, test::with_crcs_fixed(splt)})
    EXPECT_EQ(decode_error(png), "size: PNG: not a readable PNG: the file ends inside its sPLT "
                                 "chunk, which claims 1936946035 bytes");
  const std::string whole = test::rgb8_png(2, 1, std::string(1, '\0') + "abcdef");
  EXPECT_EQ(decode_error(whole.substr(0, whole.size() - 12)), // IEND left out
            "size: PNG: not a readable PNG: the file ends before IEND");
  EXPECT_EQ(decode_error(whole), "decoded");
  for (const char *name : {"png_empty_idat_null.png", "png_empty_idat_null_min.png"})
    EXPECT_EQ(decode_error(finding(name)).rfind("size: PNG: not a readable PNG: ", 0), 0u)
        << name << ": " << decode_error(finding(name));
  EXPECT_EQ(decode_error(test::rgb8_png(2, 2, std::string(64 << 20, '\0'))),
            "PNG: not a readable PNG: IDAT: Too much image data");

  // A frame of the size expected, by pixels but not by shape, is refused
  // before a row is written.
  const std::vector<std::uint8_t> bytes(whole.begin(), whole.end());
  std::vector<std::uint8_t> rgb(6, 0x55);
  std::string error;
  EXPECT_FALSE(hal::video_file::decode_png_rgb(bytes, {1, 2}, rgb, error));
  EXPECT_EQ(error, "PNG: is 2x1, not the 1x2 expected");
  EXPECT_EQ(rgb, std::vector<std::uint8_t>(6, 0x55));
}

TEST(PngSequence, FoldersWithoutPngsAreRefused) {
  const test::ScratchDir dir;
  test::write_text(dir / "notes.txt", "x");
  EXPECT_EQ(open_error(dir.path()), dir.path().string() + ": folder: no .png files");
}

TEST(PngSequence, SinkChecksPatternAndFormatAtOpen) {
  const test::ScratchDir dir;
  const auto rgb = test::make_format(PixelFormat::rgb24, 4, 4);
  const auto error = [&](const std::string &pattern, const base::VideoFormat &format) {
    try {
      auto sink = hal::output::open_png_sequence_sink(pattern, format);
    } catch (const hal::output::FileSinkError &e) {
      return std::string(e.what());
    }
    return std::string("opened");
  };
  const std::string two = (dir / "%d_%d.png").string();
  EXPECT_EQ(error(two, rgb), two + ": needs exactly one frame number (%d or %0Nd), found more");
  const std::string none = (dir / "frame.png").string();
  EXPECT_EQ(error(none, rgb), none + ": needs exactly one frame number (%d or %0Nd), found none");
  const std::string good = (dir / "%d.png").string();
  EXPECT_EQ(error(good, test::make_format(PixelFormat::yuyv, 4, 4)),
            good + ": format: yuyv cannot be written as PNG; use rgb24");
  test::write_text(dir / "file", "x");
  EXPECT_NE(error((dir / "file" / "%d.png").string(), rgb).find(": cannot create folder "),
            std::string::npos);
  EXPECT_EQ(error(good, rgb), "opened");
  EXPECT_FALSE(std::filesystem::exists(dir / "0.png")) << "opening writes no frame";
  EXPECT_FALSE(std::filesystem::exists(dir / "0.png.partial"));
}

} // namespace
} // namespace camhead
