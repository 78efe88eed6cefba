// Time alignment: interpolation at a frame's mid-exposure with a per-source
// delay, bounded extrapolation, dropouts inside the history, the ring buffer;
// then the whole chain from raw samples to a LensState for a frame.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>

#include "camhead/lens_control/lens_tracker.h"
#include "camhead/lens_control/time_alignment.h"

#include <gtest/gtest.h>

namespace camhead::lens_control {
namespace {

constexpr std::int64_t kMs = 1'000'000;

// One of the example lens profiles in the source tree.
std::filesystem::path example_lens(const char *file) {
  return std::filesystem::path(CAMHEAD_SOURCE_DIR) / "scenes/lenses" / file;
}

TEST(TimeAlignment, MidExposure) {
  EXPECT_EQ(mid_exposure_ns(1000 * kMs, 20 * kMs), 1010 * kMs);
  EXPECT_EQ(mid_exposure_ns(0, 0), 0);
}

TEST(TimeAlignment, InterpolatesAtMidExposureWithSourceDelay) {
  TimelineParams p;
  p.delay_ns = 8 * kMs; // samples are stamped 8 ms after the ring was there
  AxisTimeline tl(p);
  EXPECT_FALSE(tl.at(0));
  // A ramp of 1 count per ms as stamped: counts = t_stamp / 1 ms.
  for (std::int64_t t = 0; t <= 100 * kMs; t += 10 * kMs)
    EXPECT_TRUE(tl.push(t, double(t / kMs)));
  // A frame exposed 40..56 ms: mid-exposure 48 ms. The sample describing
  // physical time 48 ms is stamped 56 ms, so the counts are 56.
  const auto r = tl.at(mid_exposure_ns(40 * kMs, 16 * kMs));
  ASSERT_TRUE(r);
  EXPECT_NEAR(r->counts, 56.0, 1e-12);
  EXPECT_EQ(r->t_ns, 48 * kMs);
  EXPECT_TRUE(r->fresh);
  // Exactly on a (delay-corrected) sample.
  EXPECT_EQ(tl.at(52 * kMs)->counts, 60.0);
}

TEST(TimeAlignment, BoundedExtrapolation) {
  TimelineParams p;
  p.max_extrapolation_ns = 20 * kMs;
  AxisTimeline tl(p);
  for (std::int64_t t = 0; t <= 100 * kMs; t += 10 * kMs)
    tl.push(t, 2.0 * double(t / kMs)); // 2 counts per ms
  const auto near = tl.at(115 * kMs);
  EXPECT_NEAR(near->counts, 230.0, 1e-9);
  EXPECT_TRUE(near->fresh);
  EXPECT_TRUE(tl.at(120 * kMs)->fresh);
  // Beyond the bound: the value stops at the bound and is stale.
  const auto far = tl.at(500 * kMs);
  EXPECT_NEAR(far->counts, 240.0, 1e-9);
  EXPECT_FALSE(far->fresh);
  // Before the history: the oldest value, stale.
  const auto old = tl.at(-5 * kMs);
  EXPECT_EQ(old->counts, 0.0);
  EXPECT_FALSE(old->fresh);
}

TEST(TimeAlignment, DropoutInsideHistoryIsStaleAndNotExtrapolatedAcross) {
  TimelineParams p;
  p.stale_after_ns = 50 * kMs;
  AxisTimeline tl(p);
  tl.push(0, 100);
  tl.push(10 * kMs, 110);
  tl.push(300 * kMs, 400); // 290 ms without data before this one
  const auto gap = tl.at(150 * kMs);
  EXPECT_FALSE(gap->fresh);
  EXPECT_TRUE(tl.at(5 * kMs)->fresh);
  // Just after the gap: no slope across the dropout, so the value is held.
  EXPECT_EQ(tl.at(310 * kMs)->counts, 400.0);
  EXPECT_TRUE(tl.at(310 * kMs)->fresh);
}

TEST(TimeAlignment, RejectsOutOfOrderAndWrapsTheRing) {
  TimelineParams p;
  p.capacity = 4;
  AxisTimeline tl(p);
  EXPECT_TRUE(tl.push(10, 1));
  EXPECT_FALSE(tl.push(10, 2));
  EXPECT_FALSE(tl.push(5, 2));
  for (int i = 2; i <= 10; ++i)
    EXPECT_TRUE(tl.push(10 * i, i));
  EXPECT_EQ(tl.size(), 4u);
  EXPECT_FALSE(tl.at(65)->fresh); // only 70..100 are still held
  EXPECT_NEAR(tl.at(85)->counts, 8.5, 1e-12);
  EXPECT_TRUE(tl.at(85)->fresh);
}

// A sample of the axes given (GCC 12 takes a designated initializer that
// leaves members out for a missing initializer).
EncoderSample counts_at(std::int64_t t, std::optional<std::int32_t> focus,
                        std::optional<std::int32_t> iris, std::optional<std::int32_t> zoom = {}) {
  EncoderSample s;
  s.t_ns = t;
  s.focus = focus;
  s.iris = iris;
  s.zoom = zoom;
  return s;
}
EncoderSample values_at(std::int64_t t, std::optional<double> focus_m,
                        std::optional<double> f_number, std::optional<double> focal_mm = {}) {
  EncoderSample s;
  s.t_ns = t;
  s.focus_distance_m = focus_m;
  s.f_number = f_number;
  s.focal_length_mm = focal_mm;
  return s;
}

TEST(LensTracker, FrameStateFromRawSamples) {
  LensTrackerConfig cfg;
  cfg.focus.timeline.delay_ns = 5 * kMs;
  cfg.iris.timeline.delay_ns = 0;
  LensTracker tracker(LensProfile::load(example_lens("example_35mm.json")), cfg);
  // No samples yet: rest values, nothing fresh.
  const LensState rest = tracker.state_at(0);
  EXPECT_EQ(rest.focus_distance_m.value, std::numeric_limits<double>::infinity());
  EXPECT_FALSE(rest.focus_distance_m.fresh);

  // 100 Hz, focus still at the 2 m mark, iris at f/4.
  std::int64_t t = 0;
  for (int i = 0; i < 200; ++i, t += 10 * kMs)
    tracker.push(counts_at(t, 9400, 1900));
  const std::int64_t last = t - 10 * kMs;
  const LensState s = tracker.state_for_frame(last - 20 * kMs, 10 * kMs);
  EXPECT_TRUE(s.calibrated);
  EXPECT_NEAR(s.focus_distance_m.value, 2.0, 1e-9);
  EXPECT_TRUE(s.focus_distance_m.fresh);
  EXPECT_EQ(s.focus_distance_m.t_ns, last - 15 * kMs);
  EXPECT_NEAR(s.f_number.value, 4.0, 1e-9);
  EXPECT_NEAR(s.t_stop->value, 4.2, 1e-9);
  EXPECT_NEAR(s.projection_focal_length_mm.value, 35.6, 1e-9);
  EXPECT_TRUE(s.all_fresh()); // a prime's zoom quantities follow focus

  // The encoder drops out: a frame 100 ms later holds the values, stale.
  const LensState late = tracker.state_for_frame(last + 100 * kMs, 10 * kMs);
  EXPECT_NEAR(late.focus_distance_m.value, 2.0, 1e-9);
  EXPECT_FALSE(late.focus_distance_m.fresh);
  EXPECT_FALSE(late.f_number.fresh);
  EXPECT_FALSE(late.all_fresh());

  // With the uncalibrated fallback the same samples give the nominal lens.
  LensTracker fallback(LensProfile::uncalibrated());
  fallback.push(counts_at(0, 9400, 1900, 5));
  EXPECT_FALSE(fallback.state_at(0).calibrated);
}

// A source that sends physical values (a trace's focus_m, f_stop and
// focal_mm columns, an engine's OpenTrackIO focusDistance and fStop) drives
// the state: interpolated in diopters and stops, fresh while they come.
TEST(LensTracker, CalibratedValuesAloneDriveTheState) {
  LensTracker tracker(LensProfile::uncalibrated());
  tracker.push(values_at(0, 4.0, 2.0));
  tracker.push(values_at(10 * kMs, 1.0, 4.0));
  const LensState mid = tracker.state_at(5 * kMs);
  EXPECT_NEAR(mid.focus_distance_m.value, 1.0 / 0.625, 1e-9);  // halfway in diopters
  EXPECT_NEAR(mid.f_number.value, 2.0 * std::sqrt(2.0), 1e-9); // halfway in stops
  EXPECT_TRUE(mid.focus_distance_m.fresh);
  EXPECT_TRUE(mid.f_number.fresh);
  EXPECT_FALSE(mid.t_stop.has_value());
  // No focal length sent: the fallback's nominal one, and not calibrated.
  EXPECT_NEAR(mid.focal_length_mm.value, 35.0, 1e-9);
  EXPECT_FALSE(mid.calibrated);

  // With the focal length too, every axis is the sender's: calibrated.
  tracker.push(values_at(20 * kMs, std::numeric_limits<double>::infinity(), 4.0, 50.0));
  const LensState all = tracker.state_at(20 * kMs);
  EXPECT_EQ(all.focus_distance_m.value, std::numeric_limits<double>::infinity());
  EXPECT_NEAR(all.focal_length_mm.value, 50.0, 1e-9);
  EXPECT_NEAR(all.projection_focal_length_mm.value, 50.0, 1e-9);
  EXPECT_TRUE(all.calibrated);
}

// Both ways at once: the counts through a calibrated profile win (camhead's
// own calibration of this lens); with the uncalibrated fallback, the values.
TEST(LensTracker, CountsWinWithAProfileValuesWithout) {
  EncoderSample both = counts_at(0, 9400, 1900);
  both.focus_distance_m = 5.0;
  both.f_number = 8.0;
  LensTracker profiled(LensProfile::load(example_lens("example_35mm.json")));
  profiled.push(both);
  EXPECT_NEAR(profiled.state_at(0).focus_distance_m.value, 2.0, 1e-9); // the 2 m mark
  EXPECT_NEAR(profiled.state_at(0).f_number.value, 4.0, 1e-9);

  LensTracker fallback(LensProfile::uncalibrated());
  fallback.push(both);
  EXPECT_NEAR(fallback.state_at(0).focus_distance_m.value, 5.0, 1e-9);
  EXPECT_NEAR(fallback.state_at(0).f_number.value, 8.0, 1e-9);
}

// A reloaded calibration (a service's SIGHUP) maps the history it finds:
// the state is the one a tracker fed the same samples under the new profile
// gives, at once and without a sample lost.
TEST(LensTracker, ASwappedProfileMapsTheSameHistory) {
  const LensProfile prime = LensProfile::load(example_lens("example_35mm.json"));
  const LensProfile zoom = LensProfile::load(example_lens("example_zoom_24_70.json"));
  LensTracker swapped(prime), fresh(zoom);
  for (std::int64_t t = 0; t <= 200 * kMs; t += 10 * kMs) {
    const EncoderSample s = counts_at(t, std::int32_t(6000 + t / kMs * 10), 1900, 3000);
    swapped.push(s);
    fresh.push(s);
  }
  const std::int64_t mid = 105 * kMs;
  const LensState before = swapped.state_at(mid);
  swapped.set_profile(zoom);
  const LensState after = swapped.state_at(mid), expected = fresh.state_at(mid);
  EXPECT_NE(after.focal_length_mm.value, before.focal_length_mm.value) << "the profile is used";
  EXPECT_EQ(after.focus_distance_m.value, expected.focus_distance_m.value);
  EXPECT_EQ(after.f_number.value, expected.f_number.value);
  EXPECT_EQ(after.focal_length_mm.value, expected.focal_length_mm.value);
  EXPECT_EQ(after.projection_focal_length_mm.value, expected.projection_focal_length_mm.value);
  EXPECT_TRUE(after.all_fresh());
}

// A focus sent as a distance still breathes as the profile says: the
// projection focal length at 2 m is the one the counts at the 2 m mark give.
TEST(LensTracker, AFocusValueBreathesAsTheProfileSays) {
  const LensProfile profile = LensProfile::load(example_lens("example_35mm.json"));
  LensTracker by_value(profile);
  EncoderSample value = counts_at(0, std::nullopt, 1900);
  value.focus_distance_m = 2.0;
  by_value.push(value);
  LensTracker by_counts(profile);
  by_counts.push(counts_at(0, 9400, 1900));
  EXPECT_NEAR(by_value.state_at(0).projection_focal_length_mm.value,
              by_counts.state_at(0).projection_focal_length_mm.value, 1e-9);
  EXPECT_NEAR(by_value.state_at(0).projection_focal_length_mm.value, 35.6, 1e-9);
}

} // namespace
} // namespace camhead::lens_control
