// A webcam's MJPEG frame decoded to RGB as hal/camera/v4l2 decodes it
// (hal/jpeg: libjpeg-turbo's TurboJPEG, opened at run time), against the
// stb_image decoder it replaced, compiled here as the peer, into the same
// buffer: issue 26's question whether libjpeg-turbo beats stb at 1080p.
//
//   build/bench/jpeg_benchmarks --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
//
// The frame: a smooth gradient with sensor-like noise and sharp edges, so
// that the entropy coder has a camera's work to do, encoded at quality 85
// (typical of UVC webcams), 4:2:0 as stb writes it.
#include <cstdint>
#include <cstring>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "camhead/hal/jpeg/jpeg_frame.h"

#include <benchmark/benchmark.h>

#define STBI_ONLY_JPEG
#define STBI_NO_STDIO
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

namespace {

std::vector<std::uint8_t> camera_like_rgb(int width, int height) {
  std::vector<std::uint8_t> rgb(std::size_t(width) * std::size_t(height) * 3);
  std::mt19937 random(1);
  std::normal_distribution<float> noise(0.0f, 3.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const bool edge = ((x / 64) + (y / 64)) % 2 == 0; // a chequer of sharp edges
      for (int c = 0; c < 3; ++c) {
        const float base =
            40.0f + 150.0f * float(x) / float(width) + 30.0f * float(c) + (edge ? 25.0f : 0.0f);
        const float v = base + noise(random);
        rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3 + std::size_t(c)] =
            std::uint8_t(v < 0.0f     ? 0.0f
                         : v > 255.0f ? 255.0f
                                      : v);
      }
    }
  return rgb;
}

struct Frame {
  int width, height;
  std::vector<std::uint8_t> jpeg;
  std::vector<std::uint8_t> rgb; // the decoder's output buffer
};

Frame make_frame(benchmark::State &state) {
  const int width = int(state.range(0)), height = int(state.range(1));
  Frame f{width, height,
          camhead::hal::jpeg::encode_jpeg_rgb(camera_like_rgb(width, height), width, height, 85),
          std::vector<std::uint8_t>(std::size_t(width) * std::size_t(height) * 3)};
  state.counters["jpeg_kB"] = double(f.jpeg.size()) / 1000.0;
  return f;
}

// The peer: stb_image's decoder as hal/jpeg called it (it decodes into its
// own buffer, which is copied out).
void BM_DecodeStb(benchmark::State &state) {
  Frame f = make_frame(state);
  for (auto _ : state) {
    int w = 0, h = 0, channels = 0;
    stbi_uc *pixels =
        stbi_load_from_memory(f.jpeg.data(), int(f.jpeg.size()), &w, &h, &channels, 3);
    if (pixels == nullptr) {
      state.SkipWithError("stb_image refused the frame");
      break;
    }
    std::memcpy(f.rgb.data(), pixels, f.rgb.size());
    stbi_image_free(pixels);
    benchmark::DoNotOptimize(f.rgb.data());
  }
}
BENCHMARK(BM_DecodeStb)->Args({1280, 720})->Args({1920, 1080})->Unit(benchmark::kMillisecond);

void BM_DecodeTurbo(benchmark::State &state) {
  Frame f = make_frame(state);
  camhead::hal::jpeg::JpegDecoder decoder;
  std::string error;
  for (auto _ : state) {
    if (!decoder.decode_rgb(f.jpeg, f.width, f.height, f.rgb, error))
      state.SkipWithError(error.c_str());
    benchmark::DoNotOptimize(f.rgb.data());
  }
}
BENCHMARK(BM_DecodeTurbo)->Args({1280, 720})->Args({1920, 1080})->Unit(benchmark::kMillisecond);

} // namespace

BENCHMARK_MAIN();
