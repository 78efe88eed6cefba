// The live pipeline's render and output threads allocate nothing per frame
// (architecture.md: nothing in the frame loop allocates): a counting
// operator new for this test binary counts the allocations of the threads
// run_loop.cpp names camhead-render (with the CPU reference's workers,
// camhead-worker) and camhead-output, over a whole run of a camera take
// through a scene with a virtual ball, its lens pulling focus, into a Y4M
// file and the per-frame record. The renderer is prepared before the first
// frame (FrameRenderer::prepare), so there is no warm-up to leave out.
//
// Counted (tests/support/counting_new.h): C++ allocations, not the C
// library's malloc (stdio buffers its streams with it, once).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <pthread.h>
#include <sys/socket.h>
#include <unistd.h>

#include "counting_new.h"
#include "run/run_loop.h"
#include "run_test_support.h"
#include "test_support.h"
#include "tracker_sender.h"

#include <gtest/gtest.h>

namespace {

constexpr int kRender = 0, kOutput = 1;

// The bucket of the calling thread, by the name run_loop.cpp gives it.
int thread_bucket() {
  char name[16] = {};
  if (pthread_getname_np(pthread_self(), name, sizeof name) != 0)
    return -1;
  if (std::strcmp(name, "camhead-render") == 0 || std::strcmp(name, "camhead-worker") == 0)
    return kRender;
  if (std::strcmp(name, "camhead-output") == 0)
    return kOutput;
  return -1;
}

} // namespace

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;

// What a run's record holds so far: its composites (not the repeats and
// placeholders a slow start may add), those with the pose fresh, and those
// of a reload's setup.
struct RecordSoFar {
  std::size_t composites = 0, pose_fresh = 0, reloaded = 0;
};
RecordSoFar record_so_far(const fs::path &file) {
  std::ifstream in(file);
  RecordSoFar so_far;
  for (std::string line; std::getline(in, line);) {
    if (line.find("\"kind\":\"composite\"") == std::string::npos)
      continue;
    ++so_far.composites;
    so_far.pose_fresh += line.find("\"pose_fresh\":true") != std::string::npos ? 1 : 0;
    so_far.reloaded += line.find("\"setup\":1,") != std::string::npos ? 1 : 0;
  }
  return so_far;
}

class RunAllocations : public RunLoop {
protected:
  struct Counts {
    std::uint64_t render = 0, output = 0, frames_out = 0;
    std::uint64_t reprojected = 0;     // samples moved, in all the records
    std::uint64_t tracked_frames = 0;  // composites with a tracker's pose, fresh
    std::uint64_t reloaded_frames = 0; // composites of a reload's setup
    std::uint64_t preview_parts = 0;   // preview frames the page's watchers got
  };

  // A run of a take played in real time, looped, through a floor with a
  // virtual ball, with `render` as the board's render settings, for 40
  // frames; `tracked`: the pose of a FreeD head on this host panning to and
  // fro, and the run goes on until 31 frames had it fresh; `reload`: the
  // board reloaded (unchanged) once 10 frames are out, and the run goes on
  // until 10 frames are of the new setup; `watched`: the operator page on,
  // its composite and camera previews watched throughout. The runs that
  // wait for an event end on it (within 60 s), not on a count of frames that
  // a loaded machine could spend before the event came.
  Counts run(const std::string &render, bool tracked = false, bool reload = false,
             bool watched = false) {
    const int w = 96, h = 64, n = 8;
    std::vector<std::vector<std::uint8_t>> frames;
    for (int k = 0; k < n; ++k)
      frames.emplace_back(std::size_t(w) * h * 2, std::uint8_t(60 + 20 * k));
    const fs::path input = write("in.y4m", y4m_422(w, h, frames));
    const fs::path scene =
        write("ball.json", R"({"render": {"width": 96, "height": 64, "samples": 1},
      "camera": {"position": [0, 0.7, 0], "look_at": [0, 0.3, -2], "up": [0, 1, 0],
                 "focal_length_mm": 35, "sensor_width_mm": 36, "f_number": 2, "focus_distance_m": 2},
      "materials": {"grey": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
      "objects": [
        {"name": "floor", "type": "plane", "center": [0, 0, -3], "size": [10, 10], "material": "grey", "real": true},
        {"name": "ball", "type": "sphere", "center": [0.2, 0.25, -1.8], "radius": 0.25, "material": "grey", "real": false}],
      "lights": [{"name": "key", "type": "point", "position": [-1, 2, -1], "power_W": 200}]})");
    const std::uint16_t port = free_udp_port();
    // The FreeD source follows the trace in the board's list (the helper
    // closes the last source's object).
    const std::string freed = R"(}, {"name": "head", "type": "freed", "bind": "127.0.0.1",
                                 "port": )" +
                              std::to_string(port);
    RunOptions options;
    options.board =
        board(R"({"type": "file", "path": ")" + input.string() +
                  R"(", "loop": true, "realtime": true, "width": 96, "height": 64})",
              scene, R"(, "speed": 4)" + (tracked ? freed : ""),
              R"(, "render": )" + render + (tracked ? R"(, "pose": {"type": "freed"})" : ""));
    options.outputs = {"file:" + (dir_ / "out.y4m").string()};
    options.stats_file = dir_ / "stats.jsonl";
    options.frames = 40;
    options.threads = 2;
    options.status = nullptr;
    std::atomic<bool> stop_now{false};
    if (tracked || reload) {
      options.frames = 0;
      options.duration_s = 60.0;
      options.stop = &stop_now;
    }
    std::optional<Tracker> head;
    if (tracked)
      head.emplace("freed", port, 2.0, 3.0); // +-2 degrees, to and fro every 3 s
    std::atomic<bool> reload_now{false};
    std::thread reloader;
    if (reload) {
      options.reload = &reload_now;
      reloader = std::thread([&] {
        for (int i = 0; i < 6000 && record_so_far(dir_ / "stats.jsonl").composites < 10; ++i)
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        reload_now = true;
      });
    }
    std::atomic<bool> ended{false};
    std::thread stopper;
    if (options.stop != nullptr)
      stopper = std::thread([&] {
        const fs::path record = dir_ / "stats.jsonl";
        while (!ended && !stop_now) {
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
          const RecordSoFar so_far = record_so_far(record);
          stop_now = so_far.composites >= 40 && (!tracked || so_far.pose_fresh >= 31) &&
                     (!reload || so_far.reloaded >= 10);
        }
      });
    std::atomic<std::uint64_t> preview_parts{0};
    std::thread watchers;
    if (watched) {
      const std::uint16_t http_port = free_port(SOCK_STREAM);
      options.web = web::WebOptions{{"127.0.0.1", http_port}, std::nullopt};
      watchers = std::thread([&, http_port] { watch_previews(http_port, ended, preview_parts); });
    }
    test::counting_new::start(thread_bucket);
    const RunSummary summary = run_pipeline(options);
    test::counting_new::stop();
    ended = true;
    if (stopper.joinable())
      stopper.join();
    if (watchers.joinable())
      watchers.join();
    if (reloader.joinable())
      reloader.join();
    std::uint64_t reprojected = 0, tracked_frames = 0;
    for (const CompositeRecord &record : recorded_composites(dir_ / "stats.jsonl")) {
      reprojected += record.reprojected_samples;
      tracked_frames += record.pose_fresh ? 1 : 0;
    }
    return {test::counting_new::count(kRender),
            test::counting_new::count(kOutput),
            summary.frames_out,
            reprojected,
            tracked_frames,
            record_so_far(dir_ / "stats.jsonl").reloaded,
            preview_parts};
  }

  // Three preview streams (the composite, the camera and the region) read until `ended`;
  // counts the parts that came.
  static void watch_previews(std::uint16_t port, const std::atomic<bool> &ended,
                             std::atomic<std::uint64_t> &parts) {
    std::vector<int> streams;
    for (const char *view : {"composite", "camera", "region"}) {
      int fd = -1;
      while (!ended && fd < 0) { // until the page listens
        fd = ::socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in address{};
        address.sin_family = AF_INET;
        address.sin_port = htons(port);
        address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (::connect(fd, reinterpret_cast<sockaddr *>(&address), sizeof address) != 0) {
          ::close(fd);
          fd = -1;
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
      }
      if (fd < 0)
        break;
      const std::string request =
          std::string("GET /stream.mjpeg?view=") + view + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
      (void)::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
      timeval timeout{0, 100'000};
      ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
      streams.push_back(fd);
    }
    // The end of each stream so far: a part's header split between two reads.
    std::vector<std::string> tails(streams.size());
    char buffer[65536];
    while (!ended)
      for (std::size_t i = 0; i < streams.size(); ++i) {
        const ssize_t n = ::recv(streams[i], buffer, sizeof buffer, 0);
        if (n <= 0)
          continue;
        const std::string text = tails[i] + std::string(buffer, std::size_t(n));
        for (std::size_t at = text.find("X-Frame:"); at != std::string::npos;
             at = text.find("X-Frame:", at + 1))
          ++parts;
        tails[i] = text.substr(text.size() - std::min<std::size_t>(7, text.size()));
      }
    for (const int fd : streams)
      ::close(fd);
  }
};

TEST_F(RunAllocations, TheRenderAndOutputThreadsAllocateNothingOnTheCpuReference) {
  const Counts counts = run(R"({"executor": "cpu"})");
  EXPECT_EQ(counts.frames_out, 40u);
  EXPECT_EQ(counts.render, 0u);
  EXPECT_EQ(counts.output, 0u);
  // The pull's frames started with the frames before them moved
  // (render.reproject), and the record says so.
  EXPECT_GT(counts.reprojected, 0u);
}

// A reload's setup is made on the reload thread and swapped in between two
// frames: the render thread (and the new renderer's workers, which it starts
// on the reload thread) allocate nothing for it, nor does the output.
TEST_F(RunAllocations, AReloadAllocatesNothingInTheFrameLoop) {
  const Counts counts = run(R"({"executor": "cpu"})", false, true);
  EXPECT_GE(counts.frames_out, 40u);
  EXPECT_GE(counts.reloaded_frames, 10u) << "the reload was not taken within 60 s";
  EXPECT_EQ(counts.render, 0u);
  EXPECT_EQ(counts.output, 0u);
}

// A tracker's pose, read for every frame from the lens thread's history,
// adds nothing either.
TEST_F(RunAllocations, ATrackedPoseAllocatesNothingFrameAfterFrame) {
  const Counts counts = run(R"({"executor": "cpu"})", true);
  EXPECT_GE(counts.frames_out, 40u);
  EXPECT_GT(counts.tracked_frames, 30u) << "the run had the head's pose (the run gave up at 60 s)";
  EXPECT_EQ(counts.render, 0u);
  EXPECT_EQ(counts.output, 0u);
}

// The operator page, its previews watched: the frame loop shrinks each
// composite and camera frame into storage made at the start, and hands the
// page its record without a lock or an allocation (web/web_feed.h).
TEST_F(RunAllocations, WatchersOfTheOperatorPageAddNothingToTheFrameLoop) {
#ifndef CAMHEAD_TEST_WEB_MODULE
  GTEST_SKIP() << "the web module was not built (libevent-dev, libturbojpeg0-dev)";
#else
  ::setenv("CAMHEAD_WEB_MODULE", CAMHEAD_TEST_WEB_MODULE, 1);
  const Counts counts = run(R"({"executor": "cpu"})", false, false, true);
  EXPECT_EQ(counts.frames_out, 40u);
  EXPECT_GT(counts.preview_parts, 10u) << "the previews were not watched";
  EXPECT_EQ(counts.render, 0u);
  EXPECT_EQ(counts.output, 0u);
#endif
}

// The driver's own threads are not camhead's, and not counted (lavapipe's
// allocate: tests/renderer/frame_allocations_test.cpp).
TEST_F(RunAllocations, TheRenderAndOutputThreadsAllocateNothingOnTheGpu) {
  if (!test::have_vulkan())
    GTEST_SKIP() << "no Vulkan device";
  const Counts counts = run(R"({"executor": "gpu"})");
  EXPECT_EQ(counts.frames_out, 40u);
  EXPECT_EQ(counts.render, 0u);
  EXPECT_EQ(counts.output, 0u);
}

// The count works: the CPU reference's adaptive frames allocate their
// shares (frame_renderer.h says so), on the render thread.
TEST_F(RunAllocations, AdaptiveFramesOnTheCpuAreCounted) {
  const Counts counts = run(R"({"executor": "cpu", "adaptive": true})");
  EXPECT_EQ(counts.frames_out, 40u);
  EXPECT_GE(counts.render, counts.frames_out);
}

} // namespace
} // namespace camhead::pipeline
