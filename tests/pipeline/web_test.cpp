// The operator page's parts that need no server: the frame loop's hand-over
// (a triple buffer and a ring, without locks, and the feed they make), the
// preview's colours and its region view, the
// history's statistics, and who may reach the page (its address, its
// password file, a board's "http"). The server itself is tested from
// outside (tests/web: a client, and Chromium).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include "config/board.h"
#include "counting_new.h"
#include "tracking/calibration_views.h"
#include "web/camera_views.h"
#include "web/latest_value.h"
#include "web/preview_image.h"
#include "web/run_history.h"
#include "web/spsc_ring.h"
#include "web/web_access.h"
#include "web/web_feed.h"

#include <gtest/gtest.h>

namespace camhead::pipeline::web {
namespace {

namespace fs = std::filesystem;

TEST(LatestValue, TheReaderGetsTheNewestValueAndOnlyOnce) {
  LatestValue<int> value(-1);
  EXPECT_FALSE(value.take());
  EXPECT_EQ(value.front(), -1);
  value.back() = 1;
  value.publish();
  value.back() = 2;
  value.publish(); // replaces 1, which was never taken
  EXPECT_TRUE(value.take());
  EXPECT_EQ(value.front(), 2);
  EXPECT_FALSE(value.take());
  EXPECT_EQ(value.front(), 2);
}

// A writer publishing as fast as it can and a reader taking as fast as it
// can, until the reader has taken a thousand: every value it sees is whole
// (its two halves agree) and newer than the last.
TEST(LatestValue, NoValueIsSeenTornOrOutOfOrderUnderContention) {
  struct Pair {
    std::uint64_t a = 0, b = 0;
  };
  constexpr std::uint64_t kLast = ~std::uint64_t(0);
  LatestValue<Pair> value;
  std::atomic<bool> enough{false};
  std::thread writer([&] {
    for (std::uint64_t i = 1; !enough; ++i) {
      value.back() = {i, i};
      value.publish();
    }
    value.back() = {kLast, kLast};
    value.publish();
  });
  std::uint64_t last = 0, torn = 0, backwards = 0, taken = 0;
  while (last != kLast) {
    if (!value.take())
      continue;
    const Pair p = value.front();
    torn += p.a != p.b;
    backwards += p.a <= last;
    last = p.a;
    if (++taken == 1000)
      enough = true;
  }
  writer.join();
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_GE(taken, 1000u);
}

TEST(SpscRing, ValuesComeOutInOrderAndAFullRingCountsWhatItRefuses) {
  SpscRing<int> ring(3);
  for (int i = 0; i < 5; ++i)
    ring.push(i);
  EXPECT_EQ(ring.dropped(), 2u);
  EXPECT_EQ(ring.pop(), 0);
  EXPECT_EQ(ring.pop(), 1);
  ring.push(7);
  EXPECT_EQ(ring.pop(), 2);
  EXPECT_EQ(ring.pop(), 7);
  EXPECT_EQ(ring.pop(), std::nullopt);
}

// A writer pushing as fast as it can until the reader has had a thousand:
// what comes out is in order, each value once, and every value that did
// not come was refused and counted.
TEST(SpscRing, EveryValueCrossesBetweenTwoThreadsOnceOrIsCountedRefused) {
  SpscRing<std::uint64_t> ring(16);
  std::atomic<bool> enough{false}, written{false};
  std::atomic<std::uint64_t> pushed{0};
  std::thread writer([&] {
    std::uint64_t i = 0;
    for (; !enough; ++i)
      ring.push(i);
    pushed = i;
    written = true;
  });
  std::uint64_t received = 0, out_of_order = 0;
  std::optional<std::uint64_t> last;
  for (;;) {
    const bool done = written; // read before the ring: nothing comes after
    const std::optional<std::uint64_t> v = ring.pop();
    if (!v) {
      if (done)
        break;
      continue;
    }
    out_of_order += last && *v <= *last;
    last = v;
    if (++received == 1000)
      enough = true;
  }
  writer.join();
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_GE(received, 1000u);
  EXPECT_EQ(received + ring.dropped(), pushed.load());
}

// A frame of one R'G'B' colour in each pixel format, as the outputs lay it out.
std::vector<std::uint8_t> frame_of(const base::VideoFormat &f, int r, int g, int b) {
  std::vector<std::uint8_t> bytes(base::frame_bytes(f));
  const double kr = f.matrix == base::ColorMatrix::bt601 ? 0.299 : 0.2126;
  const double kb = f.matrix == base::ColorMatrix::bt601 ? 0.114 : 0.0722;
  const double y = kr * r + (1 - kr - kb) * g + kb * b;
  const double cb = (b - y) / (2 * (1 - kb)), cr = (r - y) / (2 * (1 - kr));
  const bool limited = f.range == base::ColorRange::limited;
  const auto code = [](double v) { return std::uint8_t(std::lround(std::clamp(v, 0.0, 255.0))); };
  const std::uint8_t Y = code(limited ? 16 + y * 219 / 255 : y);
  const std::uint8_t U = code(128 + cb * (limited ? 224.0 / 255 : 1.0));
  const std::uint8_t V = code(128 + cr * (limited ? 224.0 / 255 : 1.0));
  const std::size_t stride = base::row_bytes(f);
  for (int row = 0; row < f.height; ++row)
    for (int x = 0; x < f.width; ++x) {
      std::uint8_t *p = bytes.data() + stride * std::size_t(row);
      switch (f.pixel) {
      case base::PixelFormat::yuyv:
        p[x * 2] = Y;
        p[(x / 2) * 4 + 1] = U;
        p[(x / 2) * 4 + 3] = V;
        break;
      case base::PixelFormat::nv12:
        p[x] = Y;
        bytes[stride * std::size_t(f.height + row / 2) + std::size_t(x / 2) * 2] = U;
        bytes[stride * std::size_t(f.height + row / 2) + std::size_t(x / 2) * 2 + 1] = V;
        break;
      case base::PixelFormat::rgb24:
        p[x * 3] = std::uint8_t(r), p[x * 3 + 1] = std::uint8_t(g), p[x * 3 + 2] = std::uint8_t(b);
        break;
      case base::PixelFormat::bgr24:
        p[x * 3] = std::uint8_t(b), p[x * 3 + 1] = std::uint8_t(g), p[x * 3 + 2] = std::uint8_t(r);
        break;
      case base::PixelFormat::xrgb8888:
        p[x * 4] = std::uint8_t(b), p[x * 4 + 1] = std::uint8_t(g), p[x * 4 + 2] = std::uint8_t(r);
        break;
      }
    }
  return bytes;
}

// Every format, matrix and range shrinks to the colour it holds, within the
// 8-bit codes' rounding.
TEST(PreviewImage, EachFormatShrinksToTheColourItHolds) {
  const int colours[][3] = {{200, 40, 30}, {20, 180, 60}, {90, 60, 230}, {128, 128, 128}};
  for (const auto pixel :
       {base::PixelFormat::yuyv, base::PixelFormat::nv12, base::PixelFormat::rgb24,
        base::PixelFormat::bgr24, base::PixelFormat::xrgb8888})
    for (const auto matrix : {base::ColorMatrix::bt601, base::ColorMatrix::bt709})
      for (const auto range : {base::ColorRange::limited, base::ColorRange::full}) {
        const base::VideoFormat f{pixel, 1280, 720, 0, matrix, range};
        PreviewImage preview = preview_for(f);
        ASSERT_EQ(preview.width, 640);
        ASSERT_EQ(preview.height, 360);
        for (const auto &c : colours) {
          shrink_to_preview(f, frame_of(f, c[0], c[1], c[2]), preview);
          for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(preview.rgb[std::size_t(k)], c[k], 2)
                << base::describe(f) << " channel " << k << " of " << c[0] << "," << c[1] << ","
                << c[2];
        }
      }
}

// A preview pixel is the mean of the frame's pixels it covers: a one-pixel
// checker becomes its mean grey, and the picture keeps its place (the left
// half's colour stays left).
TEST(PreviewImage, APreviewPixelIsTheMeanOfItsBox) {
  const base::VideoFormat f{base::PixelFormat::rgb24, 1920, 1080, 0, base::ColorMatrix::bt709,
                            base::ColorRange::full};
  std::vector<std::uint8_t> bytes(base::frame_bytes(f));
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const bool left = x < f.width / 2;
      const std::uint8_t v = (x + y) % 2 ? 200 : 100;
      std::uint8_t *p = bytes.data() + (std::size_t(y) * f.width + x) * 3;
      p[0] = left ? v : 0, p[1] = 0, p[2] = left ? 0 : v;
    }
  PreviewImage preview = preview_for(f);
  ASSERT_EQ(preview_factor(f.width), 3);
  ASSERT_EQ(preview.width, 640);
  shrink_to_preview(f, bytes, preview);
  const auto at = [&](int x, int y, int k) {
    return int(preview.rgb[(std::size_t(y) * preview.width + x) * 3 + k]);
  };
  // 3x3 boxes of a checker hold 5 of one and 4 of the other.
  EXPECT_NEAR(at(10, 10, 0), 150, 12);
  EXPECT_EQ(at(10, 10, 2), 0);
  EXPECT_NEAR(at(600, 300, 2), 150, 12);
  EXPECT_EQ(at(600, 300, 0), 0);
}

// The region view: a preview pixel keeps its colour where the centre of
// the frame pixels it covers was traced, and is a third of it elsewhere,
// with the frame shrunk by 3 (1920 wide) or not at all (320 wide), and a
// region edge inside a box.
TEST(PreviewImage, TheRegionViewDarkensWhatWasNotTraced) {
  for (const int width : {1920, 320}) {
    const base::VideoFormat f{base::PixelFormat::rgb24, width,
                              width * 9 / 16,           0,
                              base::ColorMatrix::bt709, base::ColorRange::full};
    const std::vector<std::uint8_t> grey = frame_of(f, 150, 150, 150);
    PreviewImage preview = preview_for(f);
    const int step = preview_factor(width);
    const std::vector<renderer::PixelRect> region = {{64, 32, 256, 97}, {8, 97, 40, 120}};
    // Both into storage made before (preview_image.h): nothing allocated.
    camhead::test::counting_new::start([] { return 0; });
    shrink_to_preview(f, grey, preview);
    shade_outside(region, f.width, f.height, preview);
    camhead::test::counting_new::stop();
    EXPECT_EQ(camhead::test::counting_new::count(0), 0u) << width << " wide";
    int kept = 0;
    for (int py = 0; py < preview.height; ++py)
      for (int px = 0; px < preview.width; ++px) {
        const std::uint32_t x = std::uint32_t(px * step + step / 2),
                            y = std::uint32_t(py * step + step / 2);
        bool inside = false;
        for (const renderer::PixelRect &r : region)
          inside |= r.x0 <= x && x < r.x1 && r.y0 <= y && y < r.y1;
        kept += inside;
        for (int k = 0; k < 3; ++k)
          ASSERT_EQ(preview.rgb[(std::size_t(py) * preview.width + px) * 3 + k], inside ? 150 : 50)
              << width << " wide, preview pixel " << px << "," << py;
      }
    // As many pixels kept as the region covers, to the boxes' rounding.
    EXPECT_NEAR(kept * step * step, 192 * 65 + 32 * 23, 0.15 * (192 * 65 + 32 * 23)) << width;
  }
}

// The feed copies the composite and its region for the region view only
// while someone watches it, and the copy holds both.
TEST(WebFeed, TheRegionViewGetsTheCompositeAndItsRegion) {
  const base::VideoFormat f{base::PixelFormat::yuyv,  64, 32, 0, base::ColorMatrix::bt709,
                            base::ColorRange::limited};
  WebFeed feed(f, f);
  std::vector<std::uint8_t> image(base::frame_bytes(f), 77);
  const std::vector<renderer::PixelRect> region = {{0, 0, 16, 8}, {8, 8, 64, 16}};
  feed.composite(1, {}, 0, image, region);
  EXPECT_FALSE(feed.take_frame(View::region)) << "copied while nobody watched";
  feed.watch(View::region, 1);
  image[5] = 9;
  feed.composite(2, {}, 0, image, region);
  ASSERT_TRUE(feed.take_frame(View::region));
  const FrameCopy &copy = feed.frame(View::region);
  EXPECT_EQ(copy.frame, 2u);
  EXPECT_EQ(copy.bytes, image);
  EXPECT_TRUE(std::ranges::equal(copy.region(), region));
  EXPECT_FALSE(feed.take_frame(View::composite)) << "the composite view is not watched";
}

FeedEntry composite_at(std::int64_t output_ns, double render_ms) {
  FeedEntry e;
  e.output_ns = output_ns;
  e.record.capture_ns = output_ns - 40'000'000;
  e.record.render_start_ns = output_ns - std::int64_t(render_ms * 1e6) - 1'000'000;
  e.record.render_end_ns = output_ns - 1'000'000;
  return e;
}

TEST(RunHistory, EachStageHasItsMedianAndItsSlowFramesOverTheLastTenSeconds) {
  RunHistory history;
  const std::int64_t s = 1'000'000'000;
  // An old slow frame, outside the ten seconds.
  history.add(composite_at(100 * s, 500.0));
  for (int i = 0; i < 100; ++i) // 20 s later: 100 frames, 10 ms each but one of 90 ms
    history.add(composite_at(120 * s + std::int64_t(i) * 40'000'000, i == 50 ? 90.0 : 10.0));
  history.add({FeedEntry::Kind::repeat, 0, 124 * s, {}});
  const auto latency = history.latency();
  const StageLatency render = latency[std::size_t(Stage::render)];
  EXPECT_EQ(render.frames, 100u);
  EXPECT_NEAR(render.median_s, 0.010, 1e-9);
  EXPECT_NEAR(render.p99_s, 0.010, 1e-9); // one in 100 is the 100th percentile
  EXPECT_NEAR(latency[std::size_t(Stage::capture_to_output)].median_s, 0.040, 1e-9);
  EXPECT_EQ(history.composites(), 101u);
  EXPECT_EQ(history.fillers(), 1u);
  // The minute forgets what is older: the frame at 100 s goes once one comes at 161 s.
  history.add(composite_at(161 * s, 10.0));
  EXPECT_EQ(history.minute().front().output_ns, 120 * s);
}

TEST(WebAccess, AnAddressIsAPortOrAnAddressAndAPort) {
  EXPECT_EQ(parse_listen("8080", "--http").host, "127.0.0.1");
  EXPECT_EQ(parse_listen("8080", "--http").port, 8080);
  EXPECT_EQ(parse_listen("0.0.0.0:80", "--http").host, "0.0.0.0");
  EXPECT_EQ(parse_listen("[::1]:9000", "--http").host, "::1");
  EXPECT_EQ(parse_listen("localhost:9000", "--http").port, 9000);
  for (const char *wrong :
       {"", "http", "8080x", "70000", "1.2.3:80", "host.example:80", "[::1]8080", "127.0.0.1:"}) {
    try {
      (void)parse_listen(wrong, "--http");
      ADD_FAILURE() << "'" << wrong << "' taken";
    } catch (const WebAccessError &e) {
      EXPECT_NE(std::string(e.what()).find(std::string("--http: '") + wrong + "'"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_TRUE(is_loopback("127.0.0.1"));
  EXPECT_TRUE(is_loopback("127.1.2.3"));
  EXPECT_TRUE(is_loopback("::1"));
  EXPECT_FALSE(is_loopback("0.0.0.0"));
  EXPECT_FALSE(is_loopback("192.168.1.20"));
  EXPECT_FALSE(is_loopback("::"));
}

// A calibration view is the camera's luma exactly, as `calibrate camera`
// reads it back; the views of one lens position share a folder, numbered
// on from the highest there; without the focus counts nothing is saved.
TEST(CameraViews, EachViewIsTheLumaInTheFolderOfItsLensPosition) {
  const fs::path dir = fs::temp_directory_path() / ("camhead_views_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  std::vector<std::uint8_t> luma(64 * 48);
  for (std::size_t i = 0; i < luma.size(); ++i)
    luma[i] = std::uint8_t(i * 7 % 251);
  const LumaImage image{luma.data(), 64, 48, 64};
  SavedView first, second, zoomed, none;
  ASSERT_EQ(save_camera_view(dir, image, {9400, std::nullopt}, first), "");
  EXPECT_EQ(first.file, fs::absolute(dir / "camera-views" / "focus-9400" / "view-001.png"));
  EXPECT_EQ(first.at, "focus=9400");
  EXPECT_EQ(first.views, 1);
  fs::remove(first.file.parent_path() / "view-001.png");
  std::ofstream(first.file.parent_path() / "view-007.png") << "a view taken before";
  ASSERT_EQ(save_camera_view(dir, image, {9400, std::nullopt}, second), "");
  EXPECT_EQ(second.file.filename(), "view-008.png");
  EXPECT_EQ(second.views, 2);
  ASSERT_EQ(save_camera_view(dir, image, {9400, 120}, zoomed), "");
  EXPECT_EQ(zoomed.file.parent_path().filename(), "focus-9400-zoom-120");
  EXPECT_EQ(zoomed.at, "focus=9400,zoom=120");
  const std::vector<CalibrationPicture> read = read_calibration_views({second.file}, 1);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].width, 64);
  EXPECT_EQ(read[0].height, 48);
  EXPECT_EQ(read[0].luma, luma);
  EXPECT_FALSE(fs::exists(second.file.string() + ".partial"));
  EXPECT_NE(save_camera_view(dir, image, {}, none).find("no focus counts"), std::string::npos);
  // A folder that cannot be made: named.
  std::ofstream(dir / "blocked") << "a file where the folder would go";
  EXPECT_NE(save_camera_view(dir / "blocked", image, {9400, std::nullopt}, none)
                .find((dir / "blocked").string()),
            std::string::npos);
  fs::remove_all(dir);
}

class PasswordFile : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("camhead_web_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  static std::string error_of(const fs::path &file) {
    try {
      (void)read_password_file(file);
    } catch (const WebAccessError &e) {
      return e.what();
    }
    return "(no error)";
  }
  fs::path dir_;
};

TEST_F(PasswordFile, WrittenOnlyForItsOwnerAndReadBack) {
  const fs::path file = dir_ / "web-password";
  write_password_file(file, "$y$j9T$salt$hash");
  struct stat st {};
  ASSERT_EQ(::stat(file.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(read_password_file(file), "$y$j9T$salt$hash");
  EXPECT_FALSE(fs::exists(dir_ / "web-password.partial"));
}

// The package's file belongs to the service's user; root setting the
// password must not take it away from the service.
TEST_F(PasswordFile, ASetPasswordKeepsTheFilesOwner) {
  if (::geteuid() != 0)
    GTEST_SKIP() << "only root can give a file to another user";
  const fs::path file = dir_ / "web-password";
  { std::ofstream{file}; }
  ASSERT_EQ(::chown(file.c_str(), 65534, 65534), 0);
  write_password_file(file, "$y$j9T$salt$hash");
  struct stat st {};
  ASSERT_EQ(::stat(file.c_str(), &st), 0);
  EXPECT_EQ(st.st_uid, 65534u);
  EXPECT_EQ(st.st_gid, 65534u);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
}

TEST_F(PasswordFile, AFileOthersCanReadAnEmptyOneOrNoneIsRefusedByName) {
  const fs::path file = dir_ / "web-password";
  EXPECT_NE(error_of(file).find(file.string() + ": No such file"), std::string::npos)
      << error_of(file);
  write_password_file(file, "$y$j9T$salt$hash");
  fs::permissions(file, fs::perms::group_read, fs::perm_options::add);
  EXPECT_NE(error_of(file).find("others may read or change it (mode 0640): `chmod 600"),
            std::string::npos)
      << error_of(file);
  { std::ofstream(file) << "password123\n"; }
  fs::permissions(file, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_NE(error_of(file).find("holds no password hash"), std::string::npos) << error_of(file);
}

TEST(BoardHttp, ABoardTurnsThePageOnAndAWrongAddressIsNamedByField) {
  const std::string head = R"({"format": "camhead-board", "version": 1, "name": "t",
      "lens": {"sources": [{"name": "pull", "type": "trace", "file": "p.csv"}]}, "http": )";
  const Board board =
      parse_board(head + R"({"listen": "0.0.0.0:8080", "password_file": "/etc/camhead/pw"}})",
                  "/rigs/test.json");
  ASSERT_TRUE(board.http);
  EXPECT_EQ(board.http->listen.host, "0.0.0.0");
  EXPECT_EQ(board.http->listen.port, 8080);
  EXPECT_EQ(board.http->password_file, fs::path("/etc/camhead/pw"));
  try {
    (void)parse_board(head + R"({"listen": "everywhere"}})", "/rigs/test.json");
    ADD_FAILURE() << "a wrong address taken";
  } catch (const BoardError &e) {
    EXPECT_NE(std::string(e.what()).find("http.listen"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'everywhere'"), std::string::npos) << e.what();
  }
}

} // namespace
} // namespace camhead::pipeline::web
