// Encoder filtering at an assumed 100 Hz encoder rate: step latency and
// still-lens jitter (both printed, so the figures appear in the test log),
// ramp lag, spike rejection, and dropout.
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <random>
#include <vector>

#include "camhead/lens_control/encoder_filter.h"

#include <gtest/gtest.h>

namespace camhead::lens_control {
namespace {

constexpr std::int64_t kDtNs = 10'000'000; // 100 Hz
constexpr double kDtS = 1e-2;

// Runs `n` samples of `signal(i)` through `push` (which returns the latest
// output after sample i, or nothing while it holds) and returns the outputs,
// holding the previous output where nothing new came out.
std::vector<double> run(int n, const std::function<double(int)> &signal,
                        const std::function<std::optional<double>(std::int64_t, double)> &push) {
  std::vector<double> out;
  double last = signal(0);
  for (int i = 0; i < n; ++i) {
    if (const auto y = push(std::int64_t(i) * kDtNs, signal(i)))
      last = *y;
    out.push_back(last);
  }
  return out;
}

auto one_euro(OneEuroFilter &f) {
  return [&f](std::int64_t t, double x) -> std::optional<double> { return f.filter(t, x); };
}

auto full_chain(EncoderFilter &f) {
  return [&f](std::int64_t t, double x) -> std::optional<double> {
    const auto r = f.push(t, std::int32_t(std::lround(x)));
    if (r.count == 0)
      return std::nullopt;
    return r.samples[std::size_t(r.count - 1)].counts;
  };
}

// Samples from the step until the output first reaches 90 % of it.
int samples_to_90(const std::vector<double> &y, int step_at, double from, double to) {
  for (int i = step_at; i < int(y.size()); ++i)
    if ((y[std::size_t(i)] - from) / (to - from) >= 0.9)
      return i - step_at;
  return int(y.size());
}

double stddev(const std::vector<double> &v, std::size_t from) {
  double mean = 0, sq = 0;
  const double n = double(v.size() - from);
  for (std::size_t i = from; i < v.size(); ++i)
    mean += v[i] / n;
  for (std::size_t i = from; i < v.size(); ++i)
    sq += (v[i] - mean) * (v[i] - mean) / n;
  return std::sqrt(sq);
}

TEST(EncoderFilter, StepLatency) {
  const int step_at = 100;
  const auto step = [&](double from, double to) {
    return [=](int i) { return i < step_at ? from : to; };
  };
  const EncoderFilterParams params;
  std::printf("[ lens ] encoder rate 100 Hz, One Euro min_cutoff %.2f Hz beta %.3f d_cutoff %.2f "
              "Hz, spike threshold %.0f counts\n",
              params.one_euro.min_cutoff_hz, params.one_euro.beta, params.one_euro.d_cutoff_hz,
              params.spike_threshold_counts);
  int large_euro = 0, large_chain = 0;
  for (const double size : {2000.0, 200.0, 40.0, 10.0}) {
    OneEuroFilter euro(params.one_euro);
    EncoderFilter chain(params);
    const int a = samples_to_90(run(400, step(1000, 1000 + size), one_euro(euro)), step_at, 1000,
                                1000 + size);
    const int b = samples_to_90(run(400, step(1000, 1000 + size), full_chain(chain)), step_at, 1000,
                                1000 + size);
    // Counted from the first sample that shows the step: 0 means that sample's
    // output already reached 90 %.
    std::printf("[ lens ] step of %5.0f counts: 90%% after %2d samples (%3.0f ms) One Euro alone, "
                "%2d samples (%3.0f ms) through the whole chain\n",
                size, a, a * kDtS * 1e3, b, b * kDtS * 1e3);
    if (size == 2000.0) {
      large_euro = a;
      large_chain = b;
    }
    // The spike rejector adds at most one sample, and only to jumps above
    // its threshold; the still hold at most one (it trails the filter by
    // less than its band).
    const int spike_hold = size > params.spike_threshold_counts ? 1 : 0;
    const int still_hold = params.hold_counts > 0.0 ? 1 : 0;
    EXPECT_LE(b - a, spike_hold + still_hold) << size;
  }
  // A large step drives the speed estimate up at once: the first update's
  // cutoff is min_cutoff + beta * alpha_d * step / dt, which for these
  // parameters gives alpha > 0.9, so one One Euro update (plus the one-sample
  // spike hold) reaches 90 %.
  const double alpha_d = OneEuroFilter::alpha(params.one_euro.d_cutoff_hz, kDtS);
  const double first_alpha = OneEuroFilter::alpha(
      params.one_euro.min_cutoff_hz + params.one_euro.beta * alpha_d * 2000.0 / kDtS, kDtS);
  std::printf("[ lens ] predicted first-update gain for the 2000-count step: %.3f\n", first_alpha);
  EXPECT_LE(large_euro, first_alpha >= 0.9 ? 1 : 2);
  EXPECT_LT(large_chain, 3);
}

TEST(EncoderFilter, RampLag) {
  // A steady focus pull at v counts/s. In steady state the output lags by L
  // counts with v dt = alpha (v dt + L), i.e. L = v dt (1 - alpha) / alpha,
  // where alpha is taken at the cutoff raised by the speed estimate, which
  // One Euro forms from x - x_hat and so settles at v + L / dt. Solve that
  // fixed point, and add one sample when a sample moves more than the spike
  // threshold (each is then held one sample).
  const EncoderFilterParams params;
  for (const double speed : {200.0, 2000.0, 8000.0}) { // counts per second
    EncoderFilter chain(params);
    const auto ramp = [=](int i) { return 1000.0 + speed * kDtS * i; };
    const std::vector<double> y = run(300, ramp, full_chain(chain));
    const double lag_ms = (ramp(299) - y.back()) / speed * 1e3;
    double lag = 0; // counts
    for (int it = 0; it < 200; ++it) {
      const double cutoff =
          params.one_euro.min_cutoff_hz + params.one_euro.beta * (speed + lag / kDtS);
      const double a = OneEuroFilter::alpha(cutoff, kDtS);
      lag = speed * kDtS * (1 - a) / a;
    }
    const bool held = speed * kDtS > params.spike_threshold_counts;
    const double predicted_ms = lag / speed * 1e3 + (held ? kDtS * 1e3 : 0.0);
    std::printf("[ lens ] ramp %5.0f counts/s: lag %5.1f ms (predicted %5.1f ms%s)\n", speed,
                lag_ms, predicted_ms, held ? ", incl. one-sample spike hold" : "");
    EXPECT_NEAR(lag_ms, predicted_ms, 0.1 * predicted_ms + 0.5);
  }
}

// 30 s of a still ring at 100 Hz: its true position between two counts, so
// quantisation flips the reading; Gaussian noise of 1 count; and a further
// random +-1 count.
std::vector<double> still_ring(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_int_distribution<int> lsb(-1, 1);
  std::vector<double> raw;
  for (int i = 0; i < 3000; ++i)
    raw.push_back(std::round(2000.4 + gauss(rng)) + lsb(rng));
  return raw;
}

TEST(EncoderFilter, StillLensJitter) {
  const std::vector<double> raw = still_ring(42);

  const EncoderFilterParams params;
  EncoderFilter chain(params);
  const std::vector<double> y = run(
      int(raw.size()), [&](int i) { return raw[std::size_t(i)]; }, full_chain(chain));
  const double raw_sd = stddev(raw, 300), out_sd = stddev(y, 300);
  // A plain low-pass at min_cutoff is the floor: white noise std falls by
  // sqrt((2 - alpha) / alpha). Noise-driven speed raises the cutoff a little.
  const double a0 = OneEuroFilter::alpha(params.one_euro.min_cutoff_hz, kDtS);
  const double floor_factor = std::sqrt((2 - a0) / a0);
  std::printf("[ lens ] still-lens jitter: raw %.3f counts rms, filtered %.3f counts rms "
              "(%.1fx lower; a fixed %.1f Hz low-pass would give %.1fx)\n",
              raw_sd, out_sd, raw_sd / out_sd, params.one_euro.min_cutoff_hz, floor_factor);
  EXPECT_GT(raw_sd / out_sd, 3.0);
  EXPECT_LT(raw_sd / out_sd, floor_factor * 1.5);
  EXPECT_EQ(chain.spikes_rejected(), 0u);
}

// The lens state a renderer sees at 25 fps, read from the filtered stream
// (every fourth of the 100 Hz samples), for the raw counts `raw`.
std::vector<double> frame_reads(const EncoderFilterParams &params, const std::vector<double> &raw) {
  EncoderFilter chain(params);
  const std::vector<double> y = run(
      int(raw.size()), [&](int i) { return raw[std::size_t(i)]; }, full_chain(chain));
  std::vector<double> frames;
  for (std::size_t i = 0; i < y.size(); i += 4)
    frames.push_back(y[i]);
  return frames;
}

TEST(EncoderFilter, AStillRingGivesTheSameValueFrameAfterFrame) {
  // StillLensJitter's noise, 30 s of it: the One Euro output alone moves
  // every frame, and a renderer would start its history afresh every frame
  // (frame_history.h); with the still hold it changes on few frames.
  const std::vector<double> raw = still_ring(7);
  const auto changed = [](const std::vector<double> &frames) {
    int n = 0;
    for (std::size_t i = 26; i < frames.size(); ++i) // from the second second on
      n += frames[i] != frames[i - 1];
    return double(n) / double(frames.size() - 26);
  };
  EncoderFilterParams no_hold;
  no_hold.hold_counts = 0.0;
  const EncoderFilterParams held;
  const double without = changed(frame_reads(no_hold, raw));
  const double with = changed(frame_reads(held, raw));
  std::printf("[ lens ] still ring, 1-count noise: the value changes on %.1f %% of frames "
              "without the hold, %.1f %% with a %.2f-count hold\n",
              100.0 * without, 100.0 * with, held.hold_counts);
  EXPECT_GT(without, 0.99);
  EXPECT_LT(with, 0.05);

  // Without noise, a ring that moved and stopped is exactly still once the
  // filter is within the band, and stays within the band of where it
  // stopped.
  std::vector<double> move(400, 3000.0);
  for (int i = 0; i < 100; ++i)
    move[std::size_t(i)] = 2000.0 + 10.0 * i;
  const std::vector<double> frames = frame_reads(held, move);
  EXPECT_EQ(frames.back(), frames[frames.size() - 25]); // the last second: one value
  EXPECT_LE(std::abs(frames.back() - 3000.0), held.hold_counts);
}

TEST(EncoderFilter, RejectsSingleSpikesOnStillAndMovingLens) {
  for (const double speed : {0.0, 1500.0}) {
    std::mt19937 rng(3);
    std::uniform_int_distribution<int> lsb(-1, 1);
    const std::vector<int> spikes_at{50, 51 + 20, 200, 333};
    EncoderFilter chain;
    std::vector<std::pair<std::int64_t, double>> out;
    for (int i = 0; i < 400; ++i) {
      const double truth = 1000 + speed * kDtS * i;
      double x = truth + lsb(rng);
      for (std::size_t k = 0; k < spikes_at.size(); ++k)
        if (spikes_at[k] == i)
          x += k % 2 ? -30000 : 5000;
      const auto r = chain.push(std::int64_t(i) * kDtNs, std::int32_t(x));
      for (int j = 0; j < r.count; ++j)
        out.emplace_back(r.samples[std::size_t(j)].t_ns, r.samples[std::size_t(j)].counts);
    }
    EXPECT_EQ(chain.spikes_rejected(), spikes_at.size()) << speed;
    for (const auto &[t, v] : out) {
      if (t < 400'000'000)
        continue; // the speed estimate is still settling on the moving lens
      const double truth = 1000 + speed * double(t) * 1e-9;
      EXPECT_NEAR(v, truth, 3.0 + speed * 0.01) << "speed " << speed << " t " << t;
    }
    // Every sample but the spikes came out (the last may still be held).
    EXPECT_GE(out.size(), 400 - spikes_at.size() - 1);
  }
}

TEST(EncoderFilter, FastMoveIsNotMistakenForSpikes) {
  // 150 counts per sample is above the spike threshold: each sample is held
  // one sample and then released, none dropped.
  EncoderFilter chain;
  int released = 0;
  for (int i = 0; i < 100; ++i)
    released += chain.push(std::int64_t(i) * kDtNs, 1000 + 150 * i).count;
  EXPECT_EQ(chain.spikes_rejected(), 0u);
  EXPECT_EQ(released, 99);
}

TEST(EncoderFilter, DropoutHoldsValueAndGoesStale) {
  EncoderFilterParams params;
  params.stale_after_ns = 50'000'000;
  EncoderFilter f(params);
  EXPECT_FALSE(f.current(0));
  std::int64_t t = 0;
  for (int i = 0; i < 100; ++i, t += kDtNs)
    (void)f.push(t, 4321);
  const std::int64_t last = t - kDtNs;
  const auto live = f.current(last + 50'000'000);
  ASSERT_TRUE(live);
  EXPECT_TRUE(live->fresh);
  EXPECT_NEAR(live->counts, 4321, 1e-9);
  const auto held = f.current(last + 50'000'001);
  EXPECT_FALSE(held->fresh);
  EXPECT_EQ(held->counts, live->counts);
  EXPECT_EQ(held->t_ns, last);
  // The encoder comes back: fresh again, and the filter catches up at once
  // (the long dt makes its gain ~1) instead of gliding from the old value.
  (void)f.push(last + 2'000'000'000, 4330);
  const auto back = f.current(last + 2'000'000'000);
  EXPECT_TRUE(back->fresh);
  EXPECT_GT(back->counts, 4329);
}

TEST(OneEuroFilter, IgnoresNonIncreasingTimestamps) {
  OneEuroFilter f;
  EXPECT_EQ(f.filter(100, 5.0), 5.0);
  EXPECT_EQ(f.filter(100, 500.0), 5.0);
  EXPECT_EQ(f.filter(50, 500.0), 5.0);
}

} // namespace
} // namespace camhead::lens_control
