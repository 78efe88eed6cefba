// What the operator page costs the frame loop (pipeline/web/web_feed.h):
// while someone watches, the output thread copies each composite for the
// page (FeedCompositeWatched), which shrinks it into the preview on its own
// thread (ShrinkToPreview: what the frame loop would pay if it shrank the
// frame itself, the first design); and hands the page the frame's record
// (FeedCompositeUnwatched: that alone). The peer in the same process is a
// plain memcpy of the frame. 720x576 YUYV is the simulated rig's frame;
// 1920x1080 a broadcast one (a quarter of it each way: 480x270).
#include <cstdint>
#include <cstring>
#include <vector>

#include "camhead/base/video_format.h"
#include "web/preview_image.h"
#include "web/web_feed.h"

#include <benchmark/benchmark.h>

namespace {

using camhead::base::PixelFormat;
using camhead::base::VideoFormat;
namespace web = camhead::pipeline::web;

VideoFormat format_of(benchmark::State &state) {
  VideoFormat f;
  f.pixel = state.range(2) == 0 ? PixelFormat::yuyv : PixelFormat::nv12;
  f.width = int(state.range(0));
  f.height = int(state.range(1));
  return f;
}

std::vector<std::uint8_t> frame_for(const VideoFormat &f) {
  std::vector<std::uint8_t> bytes(camhead::base::frame_bytes(f));
  for (std::size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = std::uint8_t(i * 2654435761u >> 24);
  return bytes;
}

void Args(benchmark::internal::Benchmark *b) {
  b->Args({720, 576, 0})->Args({1920, 1080, 0})->Args({1920, 1080, 1});
  b->ArgNames({"w", "h", "nv12"})->Unit(benchmark::kMicrosecond);
}

void BM_ShrinkToPreview(benchmark::State &state) {
  const VideoFormat f = format_of(state);
  const std::vector<std::uint8_t> frame = frame_for(f);
  web::PreviewImage preview = web::preview_for(f);
  for (auto _ : state) {
    web::shrink_to_preview(f, frame, preview);
    benchmark::DoNotOptimize(preview.rgb.data());
  }
}
BENCHMARK(BM_ShrinkToPreview)->Apply(Args);

// What the output thread calls per composite while one client watches.
void BM_FeedCompositeWatched(benchmark::State &state) {
  const VideoFormat f = format_of(state);
  const std::vector<std::uint8_t> frame = frame_for(f);
  web::WebFeed feed(f, f);
  feed.watch(web::View::composite, 1);
  camhead::pipeline::FrameRecord record;
  std::uint64_t n = 0;
  for (auto _ : state) {
    feed.composite(n, record, std::int64_t(n), frame, {});
    (void)feed.next_entry(); // the page drains it
    (void)feed.take_frame(web::View::composite);
    ++n;
  }
}
BENCHMARK(BM_FeedCompositeWatched)->Apply(Args);

// And while nobody watches: the record alone.
void BM_FeedCompositeUnwatched(benchmark::State &state) {
  const VideoFormat f = format_of(state);
  const std::vector<std::uint8_t> frame = frame_for(f);
  web::WebFeed feed(f, f);
  camhead::pipeline::FrameRecord record;
  std::uint64_t n = 0;
  for (auto _ : state) {
    feed.composite(n, record, std::int64_t(n), frame, {});
    (void)feed.next_entry();
    ++n;
  }
}
BENCHMARK(BM_FeedCompositeUnwatched)->Apply(Args);

// The peer: the frame copied whole.
void BM_CopyFrame(benchmark::State &state) {
  const VideoFormat f = format_of(state);
  const std::vector<std::uint8_t> frame = frame_for(f);
  std::vector<std::uint8_t> copy(frame.size());
  for (auto _ : state) {
    std::memcpy(copy.data(), frame.data(), frame.size());
    benchmark::DoNotOptimize(copy.data());
  }
}
BENCHMARK(BM_CopyFrame)->Apply(Args);

} // namespace

BENCHMARK_MAIN();
