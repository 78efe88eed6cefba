// The recording decorator: recording a replay gives the same trace back,
// rows reach the .partial file while recording, close() renames, and a
// reading that runs backwards is passed on but not recorded.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "camhead/hal/lens/trace/lens_trace.h"
#include "camhead/hal/lens/trace/trace_recorder.h"
#include "camhead/hal/lens/trace/trace_replay.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

using std::chrono::milliseconds;
constexpr std::int64_t kMs = 1'000'000;

class FakeClock final : public ReplayClock {
public:
  std::int64_t now = 123'456'789'000;
  std::int64_t now_ns() override { return now; }
  void sleep_until(std::int64_t t_ns) override { now = std::max(now, t_ns); }
};

// A source that hands out whatever the test queued, for odd sequences.
class ScriptedSource final : public LensEncoder {
public:
  std::vector<EncoderReading> queue;
  std::string name() const override { return "scripted"; }
  void poll(milliseconds, std::vector<EncoderReading> &out) override {
    out.insert(out.end(), queue.begin(), queue.end());
    queue.clear();
  }
  EncoderStatus status() const override {
    EncoderStatus s;
    s.detail = "scripted: fine";
    return s;
  }
};

// A unique scratch folder per test, removed at the end.
class TraceRecorderTest : public testing::Test {
protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("camhead_recorder_" + std::to_string(::getpid()) + "_" +
            testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  static std::string slurp(const std::filesystem::path &p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  std::filesystem::path dir_;
};

LensTrace sample_trace() {
  LensTrace t{"sample.csv", {}};
  for (int i = 0; i < 50; ++i) {
    EncoderReading r;
    r.t_ns = i * 10 * kMs + (i % 3) * 1234; // uneven nanoseconds survive too
    r.focus = 13000 - 200 * i;
    r.iris = i % 7 == 0 ? std::optional<std::int32_t>{} : std::optional<std::int32_t>{600 + i};
    r.zoom = 0;
    if (i % 10 == 0) {
      r.focus_distance_m = 1.0 / (i + 1);
      r.f_stop = 2.8;
      r.focal_length_mm = 35.0;
    }
    t.readings.push_back(r);
  }
  return t;
}

TEST_F(TraceRecorderTest, RecordingAReplayGivesTheSameTrace) {
  const LensTrace original = sample_trace();
  FakeClock clock;
  TraceReplayOptions options;
  options.clock = &clock;
  const std::filesystem::path path = dir_ / "rec.csv";
  TraceRecorder recorder(std::make_unique<TraceReplay>(original, options), path);
  EXPECT_EQ(recorder.name(), "trace sample.csv");

  std::vector<EncoderReading> passed;
  while (passed.size() < original.readings.size()) {
    recorder.poll(milliseconds(100), passed);
  }
  // Passed through unchanged: the replay's own readings at their due instants.
  EXPECT_EQ(passed.front().t_ns, clock.now - (original.readings.back().t_ns));
  EXPECT_EQ(passed.back().focus, original.readings.back().focus);
  recorder.close();
  EXPECT_FALSE(std::filesystem::exists(recorder.partial_path()));
  EXPECT_EQ(recorder.recorded(), original.readings.size());

  const LensTrace back = read_lens_trace(path);
  EXPECT_EQ(back.readings, original.readings);
  const std::string text = slurp(path);
  EXPECT_EQ(text.rfind("# camhead lens trace v1\n# recorded from trace sample.csv\n", 0), 0u)
      << text.substr(0, 80);
}

TEST_F(TraceRecorderTest, RowsReachThePartialFileWhileRecording) {
  FakeClock clock;
  TraceReplayOptions options;
  options.clock = &clock;
  TraceRecorderOptions rec;
  rec.flush_interval = milliseconds(100);
  rec.comment = "take 3";
  const std::filesystem::path path = dir_ / "live.csv";
  auto recorder = std::make_unique<TraceRecorder>(
      std::make_unique<TraceReplay>(sample_trace(), options), path, rec);
  EXPECT_TRUE(std::filesystem::exists(recorder->partial_path()));
  EXPECT_FALSE(std::filesystem::exists(path));

  std::vector<EncoderReading> passed;
  while (passed.size() < 25) { // 240 ms of readings: more than one interval
    recorder->poll(milliseconds(100), passed);
  }
  // What is on disk now is a valid trace of a prefix of the readings: a crash
  // here would lose less than one flush interval.
  const LensTrace partial = parse_lens_trace(slurp(recorder->partial_path()), "partial");
  EXPECT_GE(partial.readings.size(), 10u);
  EXPECT_LE(partial.readings.size(), 25u);
  EXPECT_GE(partial.readings.back().t_ns, 240 * kMs - 100 * kMs);

  recorder->close();
  EXPECT_FALSE(std::filesystem::exists(dir_ / "live.csv.partial"));
  const std::string text = slurp(path);
  EXPECT_NE(text.find("# take 3\n"), std::string::npos);
  EXPECT_EQ(parse_lens_trace(text, "live").readings.size(), 25u);
}

TEST_F(TraceRecorderTest, BackwardsReadingPassesButIsNotRecorded) {
  auto source = std::make_unique<ScriptedSource>();
  ScriptedSource &script = *source;
  TraceRecorder recorder(std::move(source), dir_ / "odd.csv");
  script.queue.resize(3);
  script.queue[0].t_ns = 1000 * kMs;
  script.queue[0].focus = 1;
  script.queue[1].t_ns = 990 * kMs; // a clock step in the source
  script.queue[1].focus = 2;
  script.queue[2].t_ns = 1010 * kMs;
  script.queue[2].focus = 3;
  std::vector<EncoderReading> passed;
  recorder.poll(milliseconds(0), passed);
  EXPECT_EQ(passed.size(), 3u);
  EXPECT_EQ(recorder.skipped(), 1u);
  EXPECT_EQ(recorder.recorded(), 2u);
  EXPECT_EQ(recorder.status().detail, "scripted: fine");
  recorder.close();
  recorder.close(); // idempotent

  const LensTrace back = read_lens_trace(dir_ / "odd.csv");
  ASSERT_EQ(back.readings.size(), 2u);
  EXPECT_EQ(back.readings[0].t_ns, 0);
  EXPECT_EQ(back.readings[0].focus, 1);
  EXPECT_EQ(back.readings[1].t_ns, 10 * kMs);
  EXPECT_EQ(back.readings[1].focus, 3);
}

TEST_F(TraceRecorderTest, UnwritablePlaceIsNamed) {
  const std::filesystem::path path = dir_ / "missing_folder" / "x.csv";
  try {
    TraceRecorder recorder(std::make_unique<ScriptedSource>(), path);
    FAIL() << "recorded into a folder that does not exist";
  } catch (const TraceError &e) {
    EXPECT_EQ(std::string(e.what()).rfind(
                  path.string() + ": cannot create " + path.string() + ".partial: ", 0),
              0u)
        << e.what();
  }
}

// A recording that did not finish (an exception on the way: the recorder is
// destroyed without close()) leaves the trace a user had as it was, and what
// it recorded in PATH.partial.
TEST_F(TraceRecorderTest, UnfinishedRecordingLeavesTheOldTrace) {
  const std::filesystem::path path = dir_ / "take.csv";
  {
    std::ofstream old(path);
    old << "the user's trace";
  }
  {
    auto source = std::make_unique<ScriptedSource>();
    source->queue.resize(1);
    TraceRecorder recorder(std::move(source), path);
    std::vector<EncoderReading> passed;
    recorder.poll(milliseconds(0), passed);
  }
  EXPECT_EQ(slurp(path), "the user's trace");
  EXPECT_TRUE(std::filesystem::exists(dir_ / "take.csv.partial"));
}

// An output that is a device node is refused, not replaced; a symbolic link
// stands for its target, which is replaced with the link kept.
TEST_F(TraceRecorderTest, DeviceNodesAreRefusedAndLinksFollowed) {
  try {
    TraceRecorder recorder(std::make_unique<ScriptedSource>(), "/dev/null");
    recorder.close();
    FAIL() << "recorded over /dev/null";
  } catch (const TraceError &e) {
    EXPECT_NE(std::string(e.what()).find("device node"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/null"));

  const std::filesystem::path target = dir_ / "target.csv", link = dir_ / "link.csv";
  std::ofstream(target) << "an older take";
  std::filesystem::create_symlink(target, link);
  TraceRecorder recorder(std::make_unique<ScriptedSource>(), link);
  recorder.close();
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_NO_THROW((void)read_lens_trace(target));
}

} // namespace
} // namespace camhead::hal::lens
