// allocation_bound: what an adaptive allocation could still gain by weighing
// each pixel's cost as well as its noise.
//
// For a fixed number of rays, sum sigma_i^2 / n_i is least at n_i ~ sigma_i
// (what `--adaptive` estimates from its pilot); for a fixed time it is least
// at n_i ~ sigma_i / sqrt(c_i), c_i the cost of one of pixel i's samples.
// Both optima are computed here with oracle knowledge, sigma_i from F
// independent frames and c_i timed per pixel on the CPU reference (one
// thread, fastest of three), and compared with uniform sampling and with
// camhead's own adaptive allocation at the same mean rays per pixel, as
// variance x cost (lower is better; the inverse of the efficiency). When the
// cost-aware optimum gains little over the cost-blind one, allocating by
// time is not worth a pilot that measures cost.
//
//   allocation_bound --scene ar_basic|ar_demo|FILE [--width 720 --height 576]
//                    [--rpp 9] [--frames 8]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <numeric>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench_scenes.h"
#include "camhead/renderer/adaptive.h"
#include "camhead/renderer/compiled_scene.h"
#include "camhead/renderer/cpu_tracer.h"
#include "cpu_kernel.h"

namespace camhead::bench {
namespace {

struct Args {
  std::string scene = "ar_basic";
  int width = 720, height = 576;
  std::uint32_t rpp = 9;
  int frames = 8;
};

// Seconds per sample of every pixel: `samples` per pixel traced one pixel at
// a time on this thread, the fastest of `rounds` (a preempted pixel would
// otherwise look thousands of times dearer than it is).
std::vector<double> pixel_costs(const renderer::CompiledScene &scene,
                                const renderer::gpu::FrameParams &frame, std::uint32_t samples,
                                int rounds) {
  std::vector<renderer::gpu::BvhNode> nodes;
  renderer::cpu::CpuKernel kernel = renderer::cpu::make_cpu_kernel(scene, frame, nodes);
  kernel.frame.sampling = renderer::gpu::uvec4(0u, samples, samples, frame.sampling.w);
  const auto width = frame.image.x, height = frame.image.y;
  const bool has_plate = frame.image.z != 0 && scene.plate.size() == std::size_t(width) * height;
  std::vector<double> cost(std::size_t(width) * height, 1e30);
  for (int round = 0; round < rounds; ++round) {
    for (std::uint32_t y = 0; y < height; ++y) {
      for (std::uint32_t x = 0; x < width; ++x) {
        const std::size_t i = std::size_t(y) * width + x;
        glm::vec4 mixed(0.0f), real(0.0f), aux(0.0f);
        const glm::vec4 plate = has_plate ? scene.plate[i] : glm::vec4(0.0f);
        const auto start = std::chrono::steady_clock::now();
        kernel.trace_pixel(x, y, plate, has_plate, mixed, real, aux);
        const double s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        cost[i] = std::min(cost[i], s / samples);
      }
    }
    std::fprintf(stderr, "allocation_bound: timed every pixel, round %d of %d\n", round + 1,
                 rounds);
  }
  return cost;
}

// Each pixel's variance of one sample of the composite (RGB summed), from
// `frames` independent frames of `samples` samples each.
std::vector<double> sample_variances(const renderer::CompiledScene &scene,
                                     renderer::gpu::FrameParams frame, std::uint32_t samples,
                                     int frames) {
  const std::size_t values = std::size_t(frame.image.x) * frame.image.y * 3;
  std::vector<double> sum(values, 0.0), squares(values, 0.0);
  frame.sampling.z = samples;
  for (int f = 0; f < frames; ++f) {
    frame.sampling.w = 0x51ed270bu + 7919u * std::uint32_t(f);
    const renderer::RenderResult r = renderer::render_cpu(scene, frame);
    for (std::size_t v = 0; v < values; ++v) {
      sum[v] += r.composite.data[v];
      squares[v] += double(r.composite.data[v]) * r.composite.data[v];
    }
  }
  std::vector<double> variance(values / 3, 0.0);
  for (std::size_t v = 0; v < values; ++v) {
    const double mean = sum[v] / frames;
    const double frame_variance =
        std::max(0.0, squares[v] / frames - mean * mean) * frames / (frames - 1);
    variance[v / 3] += frame_variance * samples; // a frame's mean of `samples` samples
  }
  return variance;
}

// Sum of sigma_i^2 / n_i for the water-filling n_i = clamp(lambda sigma_i,
// floor, cap) that spends `rays` in all: the best any allocation with
// adaptive's pilot (the floor) and cap can do at that ray count.
double constrained_oracle_variance(const std::vector<double> &s2, double rays, double floor,
                                   double cap) {
  const auto shares = [&](double lambda) {
    double total = 0;
    for (const double v : s2) {
      total += std::clamp(lambda * std::sqrt(v), floor, cap);
    }
    return total;
  };
  double low = 0, high = 1;
  while (shares(high) < rays && high < 1e30) {
    high *= 2;
  }
  for (int step = 0; step < 100; ++step) {
    const double mid = 0.5 * (low + high);
    (shares(mid) < rays ? low : high) = mid;
  }
  double variance = 0;
  for (const double v : s2) {
    variance += v / std::clamp(low * std::sqrt(v), floor, cap);
  }
  return variance;
}

int run(const Args &args) {
  const BenchScene bench_scene = find_bench_scene(args.scene);
  const renderer::Scene scene = load_bench_scene(bench_scene, args.width, args.height);
  const renderer::CompiledScene compiled = renderer::compile_scene(scene);
  const renderer::gpu::FrameParams frame = renderer::make_frame_params(scene, int(args.rpp));

  const std::vector<double> c = pixel_costs(compiled, frame, 16, 3);
  const std::vector<double> s2 = sample_variances(compiled, frame, 4, args.frames);
  const renderer::AdaptiveSampling settings;
  const std::vector<std::uint32_t> n =
      renderer::render_cpu_adaptive(compiled, frame, settings).sample_counts;

  const double rpp = args.rpp;
  double uniform_variance = 0, uniform_cost = 0, adaptive_variance = 0, adaptive_cost = 0;
  double sum_sigma = 0, sum_sigma_cost = 0, sum_sigma_sqrt_cost = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const double sigma = std::sqrt(s2[i]);
    uniform_variance += s2[i] / rpp;
    uniform_cost += rpp * c[i];
    adaptive_variance += s2[i] / n[i];
    adaptive_cost += n[i] * c[i];
    sum_sigma += sigma;
    sum_sigma_cost += sigma * c[i];
    sum_sigma_sqrt_cost += sigma * std::sqrt(c[i]);
  }
  // At the adaptive frame's cost C: n_i = C sigma_i / sum(sigma c) gives
  // sum(sigma) sum(sigma c) / C; n_i ~ sigma_i / sqrt(c_i) gives
  // sum(sigma sqrt(c))^2 / C (Cauchy-Schwarz: never more).
  const double blind_variance = sum_sigma * sum_sigma_cost / adaptive_cost;
  const double aware_variance = sum_sigma_sqrt_cost * sum_sigma_sqrt_cost / adaptive_cost;
  const double reference = uniform_variance * uniform_cost;
  const double rays = std::accumulate(n.begin(), n.end(), 0.0);
  const double mean_cost = std::accumulate(c.begin(), c.end(), 0.0) / double(c.size());

  std::printf("%s, %dx%d, %u rpp mean; sigma from %d frames of 4 samples, cost per pixel on one "
              "thread (mean %.3f us per sample)\n",
              bench_scene.name.c_str(), args.width, args.height, args.rpp, args.frames,
              mean_cost * 1e6);
  std::printf("| allocation | variance x cost | efficiency vs uniform |\n|---|---|---|\n");
  std::printf("| uniform | %.4g | 1.00 |\n", reference);
  std::printf("| camhead --adaptive (its rays cost %.2fx the mean) | %.4g | %.2f |\n",
              adaptive_cost / rays / mean_cost, adaptive_variance * adaptive_cost,
              reference / (adaptive_variance * adaptive_cost));
  std::printf("| oracle n ~ sigma | %.4g | %.2f |\n", blind_variance * adaptive_cost,
              reference / (blind_variance * adaptive_cost));
  std::printf("| oracle n ~ sigma / sqrt(cost) | %.4g | %.2f |\n", aware_variance * adaptive_cost,
              reference / (aware_variance * adaptive_cost));
  std::printf("cost-aware over cost-blind: %.3fx\n", blind_variance / aware_variance);
  const double pilot = renderer::adaptive_pilot(settings, args.rpp);
  const double cap = settings.max_factor * rpp;
  std::printf(
      "variance at equal rays, uniform over: --adaptive %.2fx, oracle with its pilot (%.0f) "
      "and cap (%.0f) %.2fx\n",
      uniform_variance / adaptive_variance, pilot, cap,
      uniform_variance / constrained_oracle_variance(s2, rays, pilot, cap));
  return 0;
}

} // namespace
} // namespace camhead::bench

int main(int argc, char **argv) {
  camhead::bench::Args args;
  CLI::App app{"What allocating rays by cost as well as noise could gain (bench/RESULTS.md)."};
  app.add_option("--scene", args.scene, "a bench scene (ar_basic, ar_demo) or a scene file")
      ->capture_default_str();
  app.add_option("--width", args.width, "image width in pixels")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--height", args.height, "image height in pixels")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--rpp", args.rpp, "mean rays per pixel of both allocations")
      ->capture_default_str()
      ->check(CLI::Range(5u, 1024u));
  app.add_option("--frames", args.frames, "independent 4-sample frames for each pixel's sigma")
      ->capture_default_str()
      ->check(CLI::Range(2, 1000));
  CLI11_PARSE(app, argc, argv);
  try {
    return camhead::bench::run(args);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "allocation_bound: %s\n", e.what());
    return 1;
  }
}
