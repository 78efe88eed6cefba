// The simulated rig's trace, scenes/lenses/sim_focus_pull.csv: it loads, has
// the shape its generator documents, maps through the example profile to a
// pull from far to 0.4 m, and loops without a jump.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "camhead/hal/lens/trace/lens_trace.h"
#include "camhead/hal/lens/trace/trace_replay.h"
#include "camhead/lens_control/lens_profile.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

const std::filesystem::path kLenses = std::filesystem::path(CAMHEAD_SOURCE_DIR) / "scenes/lenses";

TEST(BundledTrace, LoadsAsSixSecondsAt100Hz) {
  const LensTrace t = read_lens_trace(kLenses / "sim_focus_pull.csv");
  ASSERT_EQ(t.readings.size(), 600u);
  for (std::size_t i = 0; i < t.readings.size(); ++i) {
    const EncoderReading &r = t.readings[i];
    ASSERT_EQ(r.t_ns, static_cast<std::int64_t>(i) * 10'000'000) << "row " << i;
    ASSERT_TRUE(r.focus && r.iris && r.zoom) << "row " << i;
    EXPECT_EQ(*r.zoom, 0) << "zoom is fixed";
    EXPECT_FALSE(r.focus_distance_m || r.f_stop || r.focal_length_mm) << "raw counts only";
  }
  EXPECT_LT(std::filesystem::file_size(kLenses / "sim_focus_pull.csv"), 100u * 1024);
}

TEST(BundledTrace, ExampleProfileSeesAPullFromFarToNearAndBack) {
  const LensTrace t = read_lens_trace(kLenses / "sim_focus_pull.csv");
  const auto profile = lens_control::LensProfile::load(kLenses / "example_35mm.json");
  const auto distance = [&](std::size_t i) {
    return profile.focus_distance_m(*t.readings[i].focus).value;
  };
  const auto f_number = [&](std::size_t i) { return profile.f_number(*t.readings[i].iris).value; };

  EXPECT_GT(distance(0), 10.0); // far
  EXPECT_LT(distance(0), 20.0);
  EXPECT_NEAR(distance(320), 0.4, 0.01); // 3.2 s: near, at the table's 0.4 m point
  EXPECT_GT(distance(599), 10.0);        // back to far
  EXPECT_NEAR(f_number(0), 4.0, 0.05);   // f/4
  EXPECT_NEAR(f_number(400), 2.0, 0.05); // 4.0 s: opened to f/2
  EXPECT_NEAR(f_number(599), 4.0, 0.05);

  // Exactly one spike: a single sample far from both neighbours.
  int spikes = 0;
  for (std::size_t i = 1; i + 1 < t.readings.size(); ++i) {
    const std::int32_t here = *t.readings[i].focus;
    if (std::abs(here - *t.readings[i - 1].focus) > 1000 &&
        std::abs(here - *t.readings[i + 1].focus) > 1000) {
      ++spikes;
      EXPECT_EQ(i, 300u);
    }
  }
  EXPECT_EQ(spikes, 1);

  // Noise: a held lens wobbles by a few counts, not by nothing.
  const auto [lo, hi] = std::minmax_element(
      t.readings.begin(), t.readings.begin() + 100,
      [](const EncoderReading &a, const EncoderReading &b) { return *a.focus < *b.focus; });
  EXPECT_GT(*hi->focus - *lo->focus, 0);
  EXPECT_LE(*hi->focus - *lo->focus, 5);
}

TEST(BundledTrace, LoopsWithoutAJump) {
  const LensTrace t = read_lens_trace(kLenses / "sim_focus_pull.csv");
  EXPECT_LE(std::abs(*t.readings.front().focus - *t.readings.back().focus), 5);
  EXPECT_LE(std::abs(*t.readings.front().iris - *t.readings.back().iris), 5);
  TraceReplayOptions o;
  o.loop = true;
  const TraceReplay replay(t, o);
  EXPECT_EQ(replay.period_ns(), 6'000'000'000);
}

} // namespace
} // namespace camhead::hal::lens
