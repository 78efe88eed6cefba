// A composite on its way out, as the output thread sends it (run_loop.cpp):
// before issue 24's frame-path work, each frame was copied from the
// pipeline's slot into the sink's own buffer (FrameSink::acquire()) and then
// sent; now the sink sends from the slot (frame_sink.h). `copied` is the
// path before (the same copy, then the same submit), `direct` the path now,
// in the same process. 720x576 YUYV, the simulated rig's frame; the Y4M
// file on /dev/shm where it exists (a RAM disk: the write's cost without
// the disk's), the null sink's submit only counts.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include <unistd.h>

#include "camhead/base/video_format.h"
#include "camhead/hal/output/file/file_sink.h"
#include "camhead/hal/output/null/null_sink.h"

#include <benchmark/benchmark.h>

namespace {

namespace fs = std::filesystem;
using camhead::base::VideoFormat;
using camhead::hal::output::FrameSink;

VideoFormat rig_format() {
  VideoFormat f;
  f.pixel = camhead::base::PixelFormat::yuyv;
  f.width = 720;
  f.height = 576;
  return f;
}

fs::path scratch_file() {
  std::error_code error;
  const fs::path dir =
      fs::is_directory("/dev/shm", error) ? fs::path("/dev/shm") : fs::temp_directory_path();
  return dir / ("camhead_output_bench_" + std::to_string(::getpid()) + ".y4m");
}

void send(benchmark::State &state, FrameSink &sink, bool copied) {
  const VideoFormat format = rig_format();
  std::vector<std::uint8_t> slot(camhead::base::frame_bytes(format));
  for (std::size_t i = 0; i < slot.size(); ++i)
    slot[i] = std::uint8_t(16 + i % 220);
  std::vector<std::uint8_t> sink_buffer(slot.size());
  for (auto _ : state) {
    if (copied) {
      std::memcpy(sink_buffer.data(), slot.data(), slot.size());
      benchmark::DoNotOptimize(sink_buffer.data());
    }
    if (!sink.submit(copied ? sink_buffer : slot, 0)) {
      state.SkipWithError(sink.status().detail.c_str());
      return;
    }
  }
  state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(slot.size()));
}

void null_sink(benchmark::State &state, bool copied) {
  const std::unique_ptr<FrameSink> sink = camhead::hal::output::open_null_sink(rig_format());
  send(state, *sink, copied);
}

void y4m_sink(benchmark::State &state, bool copied) {
  const fs::path path = scratch_file();
  const std::unique_ptr<FrameSink> sink =
      camhead::hal::output::open_y4m_sink(path, rig_format(), 25);
  send(state, *sink, copied);
  static_cast<void>(sink->close());
  std::error_code error;
  fs::remove(path, error);
}

} // namespace

int main(int argc, char **argv) {
  for (const bool copied : {true, false}) {
    const std::string how = copied ? "copied" : "direct";
    benchmark::RegisterBenchmark(("Output/null/720x576/yuyv/" + how).c_str(), null_sink, copied)
        ->Unit(benchmark::kMicrosecond);
    // Frames of a 25 fps minute at most, so that the file stays in memory.
    benchmark::RegisterBenchmark(("Output/y4m/720x576/yuyv/" + how).c_str(), y4m_sink, copied)
        ->Unit(benchmark::kMicrosecond)
        ->Iterations(1500);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
