// The lens the simulated camera films through (run/trace_lens.h): the
// bundled focus pull as the glass moved. Its one encoder glitch (a single
// reading 2500 counts off at 3.0 s, which the lens chain rejects) is not
// followed, and every other instant is the trace's counts through the
// profile.
#include <cmath>
#include <cstdint>

#include "camhead/hal/lens/trace/lens_trace.h"
#include "camhead/hal/lens/trace/trace_replay.h"
#include "camhead/lens_control/lens_profile.h"
#include "config/trace_curve.h"
#include "run/trace_lens.h"
#include "run_test_support.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

using hal::lens::EncoderReading;

TEST_F(RunLoop, TheSimulatedLensDoesNotFollowAnEncoderGlitch) {
  const std::optional<TraceLens> lens = TraceLens::of_board(
      board(R"({"type": "sim", "width": 64, "height": 48, "fps": 25})", real_scene(64, 48),
            R"(, "loop": true, "clock_origin": "monotonic")"));
  ASSERT_TRUE(lens.has_value());

  // What the simulated boards latch: the trace as written, glitch included.
  const hal::lens::LensTrace trace = hal::lens::read_lens_trace(kLenses / "sim_focus_pull.csv");
  const auto profile = lens_control::LensProfile::load(kLenses / "example_35mm.json");
  const double period_s = double(hal::lens::loop_period_ns(trace)) * 1e-9;
  const TraceCurve latched(trace, &EncoderReading::focus, period_s);
  const TraceCurve iris(trace, &EncoderReading::iris, period_s);
  const TraceCurve zoom(trace, &EncoderReading::zoom, period_s);
  ASSERT_GT(latched.at(3.0) - latched.at(2.99), 1000.0) << "the bundled trace's glitch moved";

  // At the glitch, the lens is where the readings around it put it.
  const auto focus_m = [&](double t_s) {
    return lens->state_at(std::int64_t(std::llround(t_s * 1e9))).focus_distance_m.value;
  };
  for (const double t_s : {2.995, 3.0, 3.005})
    EXPECT_NEAR(focus_m(t_s), focus_m(2.99), 1e-3) << "at " << t_s << " s";

  // Everywhere else, the counts as latched, through the profile: every
  // reading's instant and every half-way point of a loop and into the next.
  int compared = 0;
  for (int k = 0; k < 2 * 1200; ++k) {
    const std::int64_t t_ns = std::int64_t(k) * 5'000'000;
    const double t_s = double(t_ns) * 1e-9; // as the lens reads its instant
    if (std::abs(std::fmod(t_s, period_s) - 3.0) < 0.0101)
      continue;
    lens_control::LensCounts counts;
    counts.focus = lens_control::AxisReading{latched.at(t_s), 0, true};
    counts.iris = lens_control::AxisReading{iris.at(t_s), 0, true};
    counts.zoom = lens_control::AxisReading{zoom.at(t_s), 0, true};
    const lens_control::LensState expected = profile.evaluate(counts);
    const lens_control::LensState state = lens->state_at(t_ns);
    ASSERT_DOUBLE_EQ(state.focus_distance_m.value, expected.focus_distance_m.value)
        << "at " << t_s << " s";
    ASSERT_DOUBLE_EQ(state.f_number.value, expected.f_number.value) << "at " << t_s << " s";
    ++compared;
  }
  EXPECT_GT(compared, 2300);
}

} // namespace
} // namespace camhead::pipeline
