// Image files: float32 EXR round trips bit for bit, PNG within one 8-bit step
// of sRGB, the half-float reference EXRs load and agree with their PNGs, and
// damaged files raise ImageError naming the file instead of crashing.
#include <algorithm>
#include <bit>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "camhead/renderer/image_io.h"
#include "png_chunks.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

namespace fs = std::filesystem;

std::string read_bytes(const fs::path &path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

using test::be32;
using test::png_chunk;
// A 16-bit RGB PNG, which stb_image_write (camhead's PNG writer) cannot
// produce.
std::string png16(int w, int h, const std::vector<std::uint16_t> &rgb) {
  std::string raw;
  for (int y = 0; y < h; ++y) {
    raw += '\0'; // filter: none
    for (int i = 0; i < w * 3; ++i)
      raw += std::string{char(rgb[y * w * 3 + i] >> 8), char(rgb[y * w * 3 + i] & 0xff)};
  }
  return "\x89PNG\r\n\x1a\n" + png_chunk("IHDR", be32(w) + be32(h) + std::string{16, 2, 0, 0, 0}) +
         png_chunk("IDAT", test::zlib_compressed(raw)) + png_chunk("IEND", "");
}

// A 5x3 float RGB OpenEXR in 2x2 tiles (partial ones at the edges), written
// by hand after the file layout spec: R = x + 10 y, G = R + 100, B = R + 200.
// (tinyexr can write tiles, but the renderer keeps tinyexr private.)
std::string tiled_exr() {
  static_assert(std::endian::native == std::endian::little, "EXR fields are little-endian");
  std::string out("\x76\x2f\x31\x01\x02\x02\x00\x00", 8); // magic; version 2, tiled
  const auto i32 = [](std::int32_t v) { return std::string(reinterpret_cast<char *>(&v), 4); };
  const auto f32 = [](float v) { return std::string(reinterpret_cast<char *>(&v), 4); };
  const auto attr = [&](const std::string &name, const std::string &type, const std::string &v) {
    out += name + '\0' + type + '\0' + i32(std::int32_t(v.size())) + v;
  };
  std::string chlist;
  for (const char *c : {"B", "G", "R"}) // float, not linear, sampling 1 x 1
    chlist += std::string(c) + '\0' + i32(2) + std::string(4, '\0') + i32(1) + i32(1);
  const std::string box = i32(0) + i32(0) + i32(4) + i32(2);
  attr("channels", "chlist", chlist + '\0');
  attr("compression", "compression", std::string(1, '\0'));
  attr("dataWindow", "box2i", box);
  attr("displayWindow", "box2i", box);
  attr("lineOrder", "lineOrder", std::string(1, '\0'));
  attr("pixelAspectRatio", "float", f32(1.0f));
  attr("screenWindowCenter", "v2f", f32(0.0f) + f32(0.0f));
  attr("screenWindowWidth", "float", f32(1.0f));
  attr("tiles", "tiledesc", i32(2) + i32(2) + std::string(1, '\0')); // one level
  out += '\0';
  std::string chunks;
  std::vector<std::uint64_t> offsets;
  const std::size_t table_end = out.size() + 6 * 8;
  for (int ty = 0; ty < 2; ++ty) {
    for (int tx = 0; tx < 3; ++tx) {
      offsets.push_back(table_end + chunks.size());
      std::string data;
      for (int y = 2 * ty; y < std::min(2 * ty + 2, 3); ++y)
        for (int c = 2; c >= 0; --c) // B, G, R
          for (int x = 2 * tx; x < std::min(2 * tx + 2, 5); ++x)
            data += f32(float(x + 10 * y + 100 * c));
      chunks += i32(tx) + i32(ty) + i32(0) + i32(0) + i32(std::int32_t(data.size())) + data;
    }
  }
  for (const std::uint64_t o : offsets)
    out += std::string(reinterpret_cast<const char *>(&o), 8);
  return out + chunks;
}

class ImageIo : public ::testing::Test {
protected:
  fs::path write(const std::string &name, const std::string &bytes) const {
    return scratch_.write(name, bytes);
  }
  // Reading must either work or throw ImageError naming the file.
  bool read_fails(const fs::path &path) const {
    try {
      (void)read_image(path);
    } catch (const ImageError &e) {
      EXPECT_EQ(std::string(e.what()).rfind(path.string() + ": ", 0), 0u) << e.what();
      return true;
    }
    return false;
  }

  test::ScratchDir scratch_;
  const fs::path dir_ = scratch_.path();
};

TEST_F(ImageIo, ExrFloat32RoundTripIsBitExact) {
  Image img(37, 23, 3); // more rows than one ZIP block (16)
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  for (float &v : img.data)
    v = u(rng);
  const float specials[] = {0.0f,  -0.0f,  1e-40f,
                            3e38f, -1e30f, std::numeric_limits<float>::infinity()};
  std::copy(std::begin(specials), std::end(specials), img.data.begin());
  write_image(dir_ / "rt.exr", img);
  const Image back = read_image(dir_ / "rt.exr");
  ASSERT_EQ(back.width, 37);
  ASSERT_EQ(back.height, 23);
  ASSERT_EQ(back.channels, 3);
  EXPECT_EQ(std::memcmp(back.data.data(), img.data.data(), img.data.size() * sizeof(float)), 0);
  // Same file name, different case of extension.
  write_image(dir_ / "upper.EXR", img);
  EXPECT_EQ(read_image(dir_ / "upper.EXR").data.size(), img.data.size());
}

TEST_F(ImageIo, GreyExrIsWrittenAsYAndReadAsThreeChannels) {
  Image grey(5, 4, 1);
  for (std::size_t i = 0; i < grey.data.size(); ++i)
    grey.data[i] = float(i) * 0.25f;
  write_image(dir_ / "grey.exr", grey);
  const Image back = read_image(dir_ / "grey.exr");
  ASSERT_EQ(back.channels, 3);
  for (std::size_t i = 0; i < grey.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(back.data[i * 3 + c], grey.data[i]);
}

TEST_F(ImageIo, SrgbTransferMatchesTheReference) {
  EXPECT_FLOAT_EQ(srgb_to_linear(0.04045f), 0.04045f / 12.92f);
  EXPECT_NEAR(srgb_to_linear(0.5f), 0.21404114f, 1e-7f);
  EXPECT_FLOAT_EQ(srgb_to_linear(1.0f), 1.0f);
  EXPECT_NEAR(linear_to_srgb(0.5f), 0.73535698f, 1e-7f);
  EXPECT_FLOAT_EQ(linear_to_srgb(0.003f), 0.003f * 12.92f);
  EXPECT_EQ(linear_to_srgb(-1.0f), 0.0f); // clipped, as imageio_util.py does
  EXPECT_EQ(linear_to_srgb(7.0f), 1.0f);
  EXPECT_EQ(linear_to_srgb(std::nanf("")), 0.0f);
  for (int i = 0; i <= 1000; ++i)
    EXPECT_NEAR(srgb_to_linear(linear_to_srgb(i / 1000.0f)), i / 1000.0f, 1e-6f);
}

TEST_F(ImageIo, PngRoundTripIsWithinOneStep) {
  Image img(64, 3, 3);
  for (std::size_t i = 0; i < img.data.size(); ++i)
    img.data[i] = float(i % 193) / 192.0f;
  img.data[0] = -0.5f; // clipped to 0
  img.data[1] = 4.0f;  // clipped to 1
  img.data[2] = std::nanf("");
  write_image(dir_ / "rt.png", img);
  const Image back = read_image(dir_ / "rt.png");
  ASSERT_EQ(back.width, 64);
  ASSERT_EQ(back.channels, 3);
  for (std::size_t i = 0; i < img.data.size(); ++i) {
    const float want = linear_to_srgb(img.data[i]);
    EXPECT_NEAR(linear_to_srgb(back.data[i]), want, 0.5f / 255.0f + 1e-6f) << i;
  }
  EXPECT_EQ(back.data[0], 0.0f);
  EXPECT_EQ(back.data[1], 1.0f);
  EXPECT_EQ(back.data[2], 0.0f);
  // linear 0.5 -> sRGB 0.73536 -> 187.52 -> 188
  Image half(1, 1, 1);
  half.data[0] = 0.5f;
  write_image(dir_ / "half.png", half);
  EXPECT_FLOAT_EQ(read_image(dir_ / "half.png").data[1], srgb_to_linear(188.0f / 255.0f));
}

TEST_F(ImageIo, Reads16BitPng) {
  const fs::path path = write("deep.png", png16(2, 1, {0, 65535, 32768, 1000, 2000, 3000}));
  const Image img = read_image(path);
  ASSERT_EQ(img.width, 2);
  EXPECT_EQ(img.data[0], 0.0f);
  EXPECT_FLOAT_EQ(img.data[1], 1.0f);
  EXPECT_FLOAT_EQ(img.data[2], srgb_to_linear(32768.0f / 65535.0f));
  EXPECT_FLOAT_EQ(img.data[5], srgb_to_linear(3000.0f / 65535.0f));
}

TEST_F(ImageIo, ReferenceExrLoadsAndAgreesWithItsPng) {
  const Image exr = read_image(test::reference_dir() / "boxes_1024.exr"); // half float, ZIP, RGB
  const Image png = read_image(test::reference_dir() / "boxes_1024.png");
  ASSERT_EQ(exr.width, 720);
  ASSERT_EQ(exr.height, 576);
  ASSERT_EQ(png.data.size(), exr.data.size());
  double sum = 0.0;
  std::size_t off_by_more = 0;
  for (std::size_t i = 0; i < exr.data.size(); ++i) {
    ASSERT_TRUE(std::isfinite(exr.data[i]) && exr.data[i] >= 0.0f) << i;
    sum += exr.data[i];
    const float a = linear_to_srgb(exr.data[i]) * 255.0f;
    const float b = linear_to_srgb(png.data[i]) * 255.0f;
    off_by_more += std::abs(a - b) > 1.0f;
  }
  const double mean = sum / double(exr.data.size());
  EXPECT_GT(mean, 0.01);
  EXPECT_LT(mean, 0.5);
  EXPECT_LT(off_by_more, exr.data.size() / 1000);

  const Image plate = read_image(test::reference_dir() / "ar_basic_plate.exr");
  EXPECT_EQ(plate.width, 720);
  const Image mask = read_image(test::reference_dir() / "ar_basic_mask.exr");
  for (const float v : mask.data)
    ASSERT_TRUE(v >= 0.0f && v <= 1.0f) << v;
}

TEST_F(ImageIo, ReadsTiledExr) {
  const std::string bytes = tiled_exr();
  const Image img = read_image(write("tiled.exr", bytes));
  ASSERT_EQ(img.width, 5);
  ASSERT_EQ(img.height, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x)
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(img.at(x, y)[c], float(x + 10 * y + 100 * c)) << x << "," << y << "," << c;
}

TEST_F(ImageIo, DamagedTiledExrIsRefusedBeforeTinyexrTrustsIt) {
  const std::string good = tiled_exr();
  const std::size_t size_at = good.find(std::string("tiles\0tiledesc\0", 15)) + 15;
  const std::size_t table = size_at + 4 + 9 + 1; // "tiles" is the last attribute
  const auto message = [&](std::string bytes) {
    try {
      (void)read_image(write("bad.exr", bytes));
    } catch (const ImageError &e) {
      return std::string(e.what());
    }
    return std::string("loaded");
  };
  std::string t = good;
  t[size_at] = 8; // a 'tiles' attribute of the wrong size
  EXPECT_NE(message(t).find("malformed header attribute tiles"), std::string::npos) << message(t);
  t = good;
  t[table] = 5; // the first tile's offset points into the header
  EXPECT_NE(message(t).find("bad tile offset"), std::string::npos) << message(t);
  t = good;
  std::swap_ranges(t.begin() + long(table), t.begin() + long(table) + 8,
                   t.begin() + long(table) + 8);
  EXPECT_NE(message(t).find("does not match"), std::string::npos) << message(t);
}

TEST_F(ImageIo, DamagedFilesRaiseImageError) {
  EXPECT_TRUE(read_fails(dir_ / "missing.exr"));
  EXPECT_TRUE(read_fails(dir_ / "missing.png"));
  EXPECT_TRUE(read_fails(write("text.exr", "not an image")));
  EXPECT_TRUE(read_fails(write("text.png", "not an image")));
  EXPECT_TRUE(read_fails(write("image.bmp", "BM")));
  const std::string exr = read_bytes(test::reference_dir() / "ar_basic_mask.exr");
  for (const std::size_t n : {std::size_t(0), std::size_t(4), std::size_t(8), std::size_t(100),
                              std::size_t(400), exr.size() / 2, exr.size() - 1})
    EXPECT_TRUE(read_fails(write("cut.exr", exr.substr(0, n)))) << n;
  Image img(20, 18, 3);
  write_image(dir_ / "small.png", img);
  const std::string png = read_bytes(dir_ / "small.png");
  // Every cut fails, up to one into the final IEND chunk.
  for (std::size_t n = 0; n < png.size(); n += 7)
    EXPECT_TRUE(read_fails(write("cut.png", png.substr(0, n)))) << n;
  EXPECT_TRUE(read_fails(write("cut.png", png.substr(0, png.size() - 1))));
}

TEST_F(ImageIo, CorruptedBytesNeverCrash) {
  write_image(dir_ / "small.exr", Image(19, 17, 3));
  const std::string exr = read_bytes(dir_ / "small.exr");
  std::mt19937 rng(7);
  for (std::size_t i = 0; i < exr.size(); ++i) {
    for (const char c : {'\0', '\x7f', '\xff', char(rng())}) {
      std::string t = exr;
      t[i] = c;
      (void)read_fails(write("flip.exr", t));
    }
  }
  write_image(dir_ / "small.png", Image(19, 17, 3));
  const std::string png = read_bytes(dir_ / "small.png");
  for (std::size_t i = 0; i < png.size(); ++i) {
    std::string t = png;
    t[i] = char(t[i] ^ 0x5a);
    (void)read_fails(write("flip.png", t));
  }
}

TEST_F(ImageIo, WriteRejectsInvalidImagesAndPaths) {
  EXPECT_THROW(write_image(dir_ / "a.exr", Image()), ImageError);
  EXPECT_THROW(write_image(dir_ / "a.exr", Image(2, 2, 2)), ImageError);
  Image short_data(2, 2, 3);
  short_data.data.pop_back();
  EXPECT_THROW(write_image(dir_ / "a.png", short_data), ImageError);
  EXPECT_THROW(write_image(dir_ / "a.tif", Image(2, 2, 3)), ImageError);
  EXPECT_THROW(write_image(dir_ / "no" / "such" / "dir.exr", Image(2, 2, 3)), ImageError);
  EXPECT_THROW(write_image(dir_ / "no" / "such" / "dir.png", Image(2, 2, 3)), ImageError);
}

// A small file may claim a vast image (an 809 KB EXR claiming 11585 x
// 11585 took gigabytes to decode): the claimed size is checked against what
// the caller needs, and against the reader's limit, from the header.
TEST_F(ImageIo, ClaimedSizeIsCheckedBeforeDecoding) {
  std::string bytes = tiled_exr();
  const std::string key = std::string("dataWindow") + '\0' + "box2i" + '\0';
  const std::size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const std::int32_t huge[4] = {0, 0, 11584, 11584};
  bytes.replace(at + key.size() + 4, 16, reinterpret_cast<const char *>(huge), 16);
  const fs::path path = write("bomb.exr", bytes);
  try {
    (void)read_image(path, ImageSize{5, 3});
    ADD_FAILURE() << "decoded";
  } catch (const ImageError &e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": is 11585x11585, not the 5x3 needed");
  }
  try {
    (void)read_image(path);
    ADD_FAILURE() << "decoded";
  } catch (const ImageError &e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": unsupported data window size");
  }
  // The right size still reads.
  EXPECT_EQ(read_image(write("tiled.exr", tiled_exr()), ImageSize{5, 3}).width, 5);
}

// An empty IDAT chunk is valid PNG (stb_image, the reader before libpng,
// copied from a null pointer for it). The image reads the same with it.
TEST_F(ImageIo, EmptyIdatChunkReadsAsWithout) {
  const std::vector<std::uint16_t> rgb = {0, 1000, 65535, 30000, 20000, 10000};
  const std::string plain = png16(2, 1, rgb);
  std::string with_empty = plain;
  const std::size_t idat = with_empty.find("IDAT") - 4;
  with_empty.insert(idat, std::string("\0\0\0\0IDAT\x35\xaf\x06\x1e", 12));
  const Image a = read_image(write("plain.png", plain));
  const Image b = read_image(write("empty_idat.png", with_empty));
  EXPECT_EQ(a.data, b.data);
}

// A small PNG whose image data inflates far beyond its header's image (a
// 207-byte one made stb_image, the reader before libpng, reallocate 2 GiB)
// is refused; libpng inflates into the image's rows and a small buffer.
TEST_F(ImageIo, InflationBombPngIsRefused) {
  const std::string png = test::rgb8_png(2, 2, std::string(64 << 20, '\0')); // 64 MiB
  const fs::path path = write("bomb.png", png);
  try {
    (void)read_image(path);
    ADD_FAILURE() << "decoded";
  } catch (const ImageError &e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() + ": not a readable PNG: IDAT: Too much image data");
  }
}

// What tests/fuzz found, kept: each file is refused with ImageError and
// nothing else (the ASan+UBSan build checks that nothing else happens). The
// PNGs also with their CRCs made right, which libpng checks first.
TEST_F(ImageIo, FuzzFindingsAreRefused) {
  const fs::path findings = test::source_dir() / "tests/assets/fuzz";
  for (const char *name : {"exr_piz_overflow_1.exr", "exr_piz_overflow_2.exr",
                           "exr_chunk_count_oom.exr", "exr_uint_overrun.exr"})
    EXPECT_TRUE(read_fails(findings / name)) << name;
  for (const char *name :
       {"png_inflate_oom_1.png", "png_inflate_oom_2.png", "png_empty_idat_null.png",
        "png_inflate_oom_1_min.png", "png_inflate_oom_2_min.png", "png_empty_idat_null_min.png"}) {
    EXPECT_TRUE(read_fails(findings / name)) << name;
    EXPECT_TRUE(read_fails(write(name, test::with_crcs_fixed(read_bytes(findings / name)))))
        << name;
  }
  // tinyexr sized its offset table by the chunkCount attribute (11 GB for
  // exr_chunk_count_oom.exr, which is refused above for its integer
  // channels); here the attribute alone, in a file camhead wrote.
  write_image(dir_ / "three_lines.exr", Image(4, 3, 3));
  std::string bytes = read_bytes(dir_ / "three_lines.exr");
  const std::int32_t size = 4, claimed = 1468006400;
  bytes.insert(8, std::string("chunkCount\0int\0", 15) +
                      std::string(reinterpret_cast<const char *>(&size), 4) +
                      std::string(reinterpret_cast<const char *>(&claimed), 4));
  const fs::path chunks = write("chunk_count.exr", bytes);
  try {
    (void)read_image(chunks);
    ADD_FAILURE() << "decoded";
  } catch (const ImageError &e) {
    EXPECT_EQ(std::string(e.what()),
              chunks.string() + ": chunkCount is 1468006400; its data window needs 1");
  }
  // tinyexr read 3 bytes past a cut-short chunk of a 32-bit integer channel.
  const fs::path uint = test::source_dir() / "tests/assets/fuzz/exr_uint_overrun.exr";
  try {
    (void)read_image(uint);
    ADD_FAILURE() << "decoded";
  } catch (const ImageError &e) {
    EXPECT_EQ(std::string(e.what()),
              uint.string() + ": channel B holds 32-bit integers; only half and float channels "
                              "are read");
  }
}

// A write that fails half-way (here a file-size limit) leaves the previous
// file as it was, and no partial file beside it.
TEST_F(ImageIo, FailedWriteLeavesThePreviousFile) {
  const fs::path path = dir_ / "frame.exr";
  Image small(4, 4, 3);
  write_image(path, small);
  const std::string before = read_bytes(path);
  Image big(512, 512, 3);
  std::mt19937 rng(1);
  for (float &v : big.data)
    v = std::uniform_real_distribution<float>(0.0f, 1.0f)(rng); // incompressible
  // In a child, so that the limit and the ignored SIGXFSZ stay there.
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{64 * 1024, 64 * 1024};
    setrlimit(RLIMIT_FSIZE, &limit);
    try {
      write_image(path, big);
    } catch (const ImageError &) {
      _exit(0); // failed, as it must
    }
    _exit(1);
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the write did not fail";
  EXPECT_EQ(read_bytes(path), before);
  EXPECT_FALSE(fs::exists(dir_ / "frame.exr.partial"));
}

} // namespace
} // namespace camhead::renderer
