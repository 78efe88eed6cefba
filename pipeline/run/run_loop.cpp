#include "run_loop.h"

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <unistd.h>

#include "camhead/base/bounded_queue.h"
#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/camera/camera_source.h"
#include "camhead/hal/camera/file/file_camera.h"
#include "camhead/hal/camera/sim/simulated_camera.h"
#include "camhead/renderer/frame_budget.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/scene_loader.h"
#include "lens_camera.h"
#include "lens_hub.h"
#include "output_uri.h"

namespace camhead::pipeline {
namespace {

using namespace std::chrono_literals;
using hal::camera::CameraSource;
using hal::camera::CapturedFrame;
using hal::camera::CaptureResult;
using hal::output::FrameSink;

// What the per-frame record says of one output frame.
struct FrameRecord {
  std::uint64_t sequence = 0;
  std::int64_t capture_ns = 0;
  std::int64_t exposure_mid_ns = 0;
  std::int64_t render_start_ns = 0;
  std::int64_t render_end_ns = 0;
  double focus_m = 0.0, f_number = 0.0, focal_length_mm = 0.0;
  bool lens_fresh = false;
  std::uint32_t rpp = 0;
  std::uint64_t camera_rays = 0;
  std::uint64_t dropped_before = 0; // camera, render-busy and output-busy drops since the last
  double decode_s = 0.0, trace_s = 0.0, encode_s = 0.0;
};

// One composite on its way to the outputs: a buffer per sink.
struct Slot {
  std::vector<std::vector<std::uint8_t>> images;
  FrameRecord record;
};

// A frame nobody should mistake for a picture or for a broken one (a
// zero-filled YUV frame is green): mid grey with a darker band a fifth of
// the height across the middle.
void fill_placeholder(const base::VideoFormat &f, std::span<std::uint8_t> out) {
  const std::size_t stride = base::row_bytes(f);
  const auto grey = [&](int y) { return std::abs(y - f.height / 2) < f.height / 10 ? 0.3 : 0.5; };
  for (int y = 0; y < f.height; ++y) {
    std::uint8_t *row = out.data() + stride * std::size_t(y);
    const double g = grey(y);
    switch (f.pixel) {
    case base::PixelFormat::yuyv:
      for (int x = 0; x < f.width; x += 2) {
        const auto luma = std::uint8_t(std::lround(16 + 219 * g));
        row[2 * x] = row[2 * x + 2] = luma;
        row[2 * x + 1] = row[2 * x + 3] = 128;
      }
      break;
    case base::PixelFormat::nv12:
      std::fill_n(row, f.width, std::uint8_t(std::lround(16 + 219 * g)));
      break;
    case base::PixelFormat::rgb24:
    case base::PixelFormat::bgr24:
      std::fill_n(row, 3 * std::size_t(f.width), std::uint8_t(std::lround(255 * g)));
      break;
    case base::PixelFormat::xrgb8888:
      for (int x = 0; x < f.width; ++x) {
        std::fill_n(row + 4 * std::size_t(x), 3, std::uint8_t(std::lround(255 * g)));
        row[4 * std::size_t(x) + 3] = 0xff;
      }
      break;
    }
  }
  if (f.pixel == base::PixelFormat::nv12)
    std::fill(out.begin() + std::ptrdiff_t(stride * std::size_t(f.height)),
              out.begin() + std::ptrdiff_t(base::frame_bytes(f)), std::uint8_t(128));
}

renderer::Scene load_run_scene(const Board &board) {
  renderer::Scene scene = renderer::load_scene(*board.scene);
  // The camera decides the frame; the scene's plate is for stills.
  scene.render.width = board.camera->width;
  scene.render.height = board.camera->height;
  scene.plate.reset();
  return scene;
}

renderer::FrameCamera base_camera(const Board &board, const renderer::Scene &scene) {
  renderer::FrameCamera camera = renderer::scene_camera(scene);
  if (board.pose) {
    const auto v = [](const std::array<double, 3> &a) {
      return glm::vec3(float(a[0]), float(a[1]), float(a[2]));
    };
    camera.position = v(board.pose->position);
    camera.look_at = v(board.pose->look_at);
    camera.up = v(board.pose->up);
  }
  camera.sensor_width_mm = float(board.camera->sensor_width_mm);
  return camera;
}

renderer::Scene real_world_of(renderer::Scene scene) {
  std::erase_if(scene.objects, [](const renderer::Object &o) { return !o.real; });
  return scene;
}

// The simulated camera's picture: the scene's real objects through the lens
// at each exposure's middle, rendered by its own CPU frame renderer, with a
// new noise pattern every frame as a sensor has.
std::unique_ptr<CameraSource> open_sim_camera(const SimCameraConfig &sim,
                                              const base::VideoFormat &format,
                                              const renderer::Scene &scene,
                                              const renderer::FrameCamera &pose,
                                              const LensHub &lens, int threads) {
  auto world = std::shared_ptr<renderer::FrameRenderer>(
      renderer::make_cpu_frame_renderer(real_world_of(scene), threads));
  hal::camera::SimulatedCameraOptions options;
  options.format = format;
  options.fps = sim.fps;
  options.disconnect_after_frames = sim.disconnect_after_frames;
  options.disconnect_s = sim.disconnect_s;
  const std::uint32_t samples = sim.samples;
  auto generator = [world, format, pose, samples, &lens](std::int64_t start_ns,
                                                         std::int64_t exposure_ns,
                                                         std::span<std::uint8_t> out) {
    const LensSnapshot snapshot = lens.state_at(start_ns + exposure_ns / 2);
    renderer::FrameRequest request;
    request.camera = lens_camera(pose, snapshot.state);
    request.rays_per_pixel = samples;
    request.seed = std::uint32_t(start_ns / 1000) | 1u;
    const renderer::VideoBuffer target{format, out};
    (void)world->render(request, {format, {}}, std::span(&target, 1));
  };
  return hal::camera::open_simulated_camera(options, std::move(generator));
}

std::unique_ptr<CameraSource> open_camera(const Board &board, const renderer::Scene &scene,
                                          const renderer::FrameCamera &pose, const LensHub &lens,
                                          int threads) {
  const CameraConfig &c = *board.camera;
  base::VideoFormat format;
  format.pixel = c.format;
  format.width = c.width;
  format.height = c.height;
  if (const auto *sim = std::get_if<SimCameraConfig>(&c.kind))
    return open_sim_camera(*sim, format, scene, pose, lens, threads);
  const auto &file = std::get<FileCameraConfig>(c.kind);
  auto camera = hal::camera::open_file_camera(
      {.path = file.path, .loop = file.loop, .realtime = file.realtime, .fps = 0.0});
  const base::VideoFormat got = camera->format();
  if (got.width != c.width || got.height != c.height)
    throw std::runtime_error(board.file.string() + ": camera: " + file.path.string() + " is " +
                             std::to_string(got.width) + "x" + std::to_string(got.height) +
                             ", the board says " + std::to_string(c.width) + "x" +
                             std::to_string(c.height));
  return camera;
}

double camera_fps(const CameraSource &camera) {
  const std::int64_t interval = camera.frame_interval_ns();
  return interval > 0 ? 1e9 / double(interval) : 25.0;
}

// The counters every thread adds to; the status line and the summary read them.
struct Counters {
  std::atomic<std::uint64_t> frames_in{0}, frames_out{0}, render_busy{0}, output_busy{0},
      render_failed{0}, placeholders{0}, repeats{0}, sink_errors{0};
  std::atomic<std::uint32_t> rpp{0};
  std::atomic<std::int64_t> latency_ns{0}; // capture to output, last frame
  std::atomic<bool> camera_lost{false};
};

void write_record(std::FILE *out, const FrameRecord &r, std::int64_t output_ns,
                  const std::string &executor) {
  std::fprintf(out,
               "{\"sequence\":%" PRIu64 ",\"capture_ns\":%" PRId64 ",\"exposure_mid_ns\":%" PRId64
               ",\"render_start_ns\":%" PRId64 ",\"render_end_ns\":%" PRId64
               ",\"output_ns\":%" PRId64 ",\"focus_m\":%s,\"f_number\":%.6g"
               ",\"focal_length_mm\":%.6g,\"lens_fresh\":%s,\"rpp\":%u,\"camera_rays\":%" PRIu64
               ",\"dropped_before\":%" PRIu64 ",\"decode_ms\":%.3f,\"trace_ms\":%.3f"
               ",\"encode_ms\":%.3f,\"executor\":\"%s\"}\n",
               r.sequence, r.capture_ns, r.exposure_mid_ns, r.render_start_ns, r.render_end_ns,
               output_ns, std::isfinite(r.focus_m) ? std::to_string(r.focus_m).c_str() : "null",
               r.f_number, r.focal_length_mm, r.lens_fresh ? "true" : "false", r.rpp, r.camera_rays,
               r.dropped_before, 1e3 * r.decode_s, 1e3 * r.trace_s, 1e3 * r.encode_s,
               executor.c_str());
}

} // namespace

RunSummary run_pipeline(const RunOptions &options) {
  const Board &board = options.board;
  if (!board.camera)
    throw std::runtime_error(board.file.string() +
                             ": camera: missing: this board has no camera for `camhead run`");
  const Executor executor = options.executor.value_or(board.render.executor);
  if (executor == Executor::gpu)
    throw std::runtime_error(
        "executor gpu: live frames on the GPU tracer are not built yet (the camera-format "
        "kernels are to come); use cpu or auto");

  // Everything that can fail is opened before the first frame.
  const renderer::Scene scene = load_run_scene(board);
  const renderer::FrameCamera pose = base_camera(board, scene);
  std::vector<OutputSpec> specs;
  for (const std::string &uri : options.outputs.empty() ? board.outputs : options.outputs)
    specs.push_back(parse_output_uri(uri));
  if (specs.empty())
    throw std::runtime_error("no output: give --output URI, or \"outputs\" in " +
                             board.file.string());
  std::unique_ptr<renderer::FrameRenderer> renderer =
      renderer::make_cpu_frame_renderer(scene, options.threads);
  LensHub lens(board);
  std::unique_ptr<CameraSource> camera = open_camera(board, scene, pose, lens, options.threads);
  const double fps = camera_fps(*camera);
  std::vector<std::unique_ptr<FrameSink>> sinks;
  for (const OutputSpec &spec : specs)
    sinks.push_back(open_output(spec, board.camera->width, board.camera->height, fps));
  std::FILE *stats = nullptr;
  if (options.stats_file) {
    stats = std::fopen(options.stats_file->c_str(), "w");
    if (stats == nullptr)
      throw std::runtime_error(options.stats_file->string() + ": cannot be written");
  }
  const std::string executor_name = renderer->executor();

  // The output slots: every buffer the loop uses, made now.
  constexpr int kSlots = 3;
  std::vector<Slot> slots(kSlots);
  for (Slot &slot : slots)
    for (const auto &sink : sinks)
      slot.images.emplace_back(base::frame_bytes(sink->format()));
  base::BoundedQueue<int> free_slots(kSlots), ready_slots(kSlots);
  for (int i = 0; i < kSlots; ++i)
    (void)free_slots.push(i);
  base::BoundedQueue<CapturedFrame> captured(1);

  Counters counters;
  std::atomic<bool> stopping{false};
  const std::int64_t start_ns = base::monotonic_ns();
  const auto should_stop = [&] {
    if (stopping || (options.stop != nullptr && *options.stop))
      return true;
    if (options.duration_s > 0.0 &&
        double(base::monotonic_ns() - start_ns) * 1e-9 >= options.duration_s)
      return true;
    return options.frames > 0 && counters.frames_out >= options.frames;
  };

  std::thread capture_thread([&] {
    while (!should_stop()) {
      CapturedFrame frame;
      const CaptureResult result = camera->wait_frame(100ms, frame);
      counters.camera_lost = result == CaptureResult::disconnected;
      if (result == CaptureResult::ended) {
        stopping = true;
        break;
      }
      if (result != CaptureResult::frame)
        continue;
      ++counters.frames_in;
      if (std::optional<CapturedFrame> replaced = captured.push(frame)) {
        ++counters.render_busy;
        camera->release(*replaced);
      }
    }
    captured.close();
  });

  std::thread render_thread([&] {
    renderer::FrameBudgetSettings budget_settings;
    budget_settings.target_s = 1.0 / fps;
    budget_settings.min_rpp = board.render.min_rays_per_pixel;
    budget_settings.max_rpp = board.render.max_rays_per_pixel;
    renderer::FrameBudget budget(budget_settings);
    std::uint64_t last_sequence = 0;
    bool first = true;
    for (;;) {
      std::optional<CapturedFrame> frame = captured.pop(100ms);
      if (!frame) {
        if (captured.closed())
          break;
        continue;
      }
      std::optional<int> slot_index = free_slots.pop(200ms);
      if (!slot_index) {
        ++counters.output_busy;
        camera->release(*frame);
        continue;
      }
      Slot &slot = slots[std::size_t(*slot_index)];
      FrameRecord &r = slot.record;
      r = {};
      r.sequence = frame->sequence;
      r.capture_ns = frame->timestamp_ns;
      r.exposure_mid_ns = hal::camera::mid_exposure_ns(*frame);
      // The camera frames since the last one rendered that will never be
      // output: lost by the camera, replaced while this thread was busy, or
      // without an output slot.
      r.dropped_before = first ? frame->sequence : frame->sequence - last_sequence - 1;
      first = false;
      last_sequence = frame->sequence;

      const LensSnapshot lens_now = lens.state_at(r.exposure_mid_ns);
      r.focus_m = lens_now.state.focus_distance_m.value;
      r.f_number = lens_now.state.f_number.value;
      r.focal_length_mm = lens_now.state.focal_length_mm.value;
      r.lens_fresh = lens_now.fresh;
      renderer::FrameRequest request;
      request.camera = lens_camera(pose, lens_now.state);
      request.rays_per_pixel = board.render.rays_per_pixel.value_or(budget.rpp());
      request.adaptive = board.render.adaptive;
      request.seed = std::uint32_t(frame->sequence * 2654435761u) | 1u;
      r.rpp = request.rays_per_pixel;

      std::vector<renderer::VideoBuffer> targets;
      targets.reserve(sinks.size());
      for (std::size_t i = 0; i < sinks.size(); ++i)
        targets.push_back({sinks[i]->format(), slot.images[i]});
      r.render_start_ns = base::monotonic_ns();
      const renderer::FrameReport report =
          renderer->render(request, {frame->format, frame->bytes}, targets);
      r.render_end_ns = base::monotonic_ns();
      camera->release(*frame);
      if (report.status != renderer::FrameStatus::ok) {
        ++counters.render_failed;
        (void)free_slots.push(*slot_index);
        continue;
      }
      r.camera_rays = report.camera_rays;
      r.decode_s = report.decode_s;
      r.trace_s = report.trace_s;
      r.encode_s = report.encode_s;
      budget.measured(request.rays_per_pixel, report.decode_s + report.trace_s + report.encode_s);
      counters.rpp = request.rays_per_pixel;
      (void)ready_slots.push(*slot_index);
    }
    ready_slots.close();
  });

  // The last frame each sink showed, to show again when the camera is slow.
  std::vector<std::vector<std::uint8_t>> last_frames;
  for (const auto &sink : sinks)
    last_frames.emplace_back(base::frame_bytes(sink->format()));
  std::thread output_thread([&] {
    // A consumer (a browser on the loopback webcam) must never go a second
    // without a frame: without a composite for this long, the last one
    // again, or the placeholder while there is no camera (or none yet).
    constexpr std::int64_t kRepeatAfterNs = 500'000'000;
    std::int64_t last_output_ns = base::monotonic_ns();
    bool shown_any = false;
    const auto send = [&](auto &&fill, std::int64_t capture_ns) {
      for (std::size_t i = 0; i < sinks.size(); ++i) {
        std::span<std::uint8_t> buffer = sinks[i]->acquire();
        if (buffer.size() < base::frame_bytes(sinks[i]->format())) {
          ++counters.sink_errors;
          continue;
        }
        fill(i, buffer);
        if (!sinks[i]->submit(capture_ns))
          ++counters.sink_errors;
      }
      last_output_ns = base::monotonic_ns();
    };
    for (;;) {
      std::optional<int> slot_index = ready_slots.pop(100ms);
      if (!slot_index) {
        if (ready_slots.closed())
          break;
        if (base::monotonic_ns() - last_output_ns < kRepeatAfterNs)
          continue;
        if (shown_any && !counters.camera_lost) {
          send(
              [&](std::size_t i, std::span<std::uint8_t> out) {
                std::copy(last_frames[i].begin(), last_frames[i].end(), out.begin());
              },
              base::monotonic_ns());
          ++counters.repeats;
        } else {
          send([&](std::size_t i,
                   std::span<std::uint8_t> out) { fill_placeholder(sinks[i]->format(), out); },
               base::monotonic_ns());
          ++counters.placeholders;
        }
        continue;
      }
      Slot &slot = slots[std::size_t(*slot_index)];
      if (options.frames > 0 && counters.frames_out >= options.frames) {
        (void)free_slots.push(*slot_index); // rendered after the last one asked for
        continue;
      }
      send(
          [&](std::size_t i, std::span<std::uint8_t> out) {
            std::copy(slot.images[i].begin(), slot.images[i].end(), out.begin());
          },
          slot.record.capture_ns);
      const std::int64_t output_ns = base::monotonic_ns();
      counters.latency_ns = output_ns - slot.record.capture_ns;
      if (stats != nullptr)
        write_record(stats, slot.record, output_ns, executor_name);
      for (std::size_t i = 0; i < sinks.size(); ++i)
        last_frames[i].swap(slot.images[i]); // the slot takes the older buffer
      shown_any = true;
      ++counters.frames_out;
      (void)free_slots.push(*slot_index);
    }
  });

  // The status line: redrawn in place on a terminal, a line a second in logs.
  const bool tty = options.status != nullptr && isatty(fileno(options.status)) != 0;
  std::uint64_t last_in = 0, last_out = 0;
  std::int64_t last_ns = start_ns;
  const std::string lens_name = lens.source_name();
  if (options.status != nullptr)
    std::fprintf(options.status, "camhead run: %s -> %zu output%s, %s, lens %s\n",
                 camera->name().c_str(), sinks.size(), sinks.size() == 1 ? "" : "s",
                 executor_name.c_str(), lens_name.c_str());
  while (!should_stop() && !(captured.closed() && ready_slots.closed())) {
    std::this_thread::sleep_for(tty ? 250ms : 1000ms);
    const std::int64_t now = base::monotonic_ns();
    if (options.status == nullptr || now - last_ns < 900'000'000)
      continue;
    const double dt = double(now - last_ns) * 1e-9;
    const std::uint64_t in = counters.frames_in, out = counters.frames_out;
    const hal::camera::CameraStatus cam = camera->status();
    const LensSnapshot lens_state = lens.state_at(now);
    char focus[32];
    if (std::isinf(lens_state.state.focus_distance_m.value))
      std::snprintf(focus, sizeof focus, "inf");
    else
      std::snprintf(focus, sizeof focus, "%.2f m", lens_state.state.focus_distance_m.value);
    std::fprintf(options.status,
                 "%sin %5.1f fps  out %5.1f fps  rpp %u  dropped %" PRIu64 " (camera %" PRIu64
                 ", render busy %" PRIu64 ")  focus %s f/%.1f %.0f mm%s  latency %.0f ms%s%s",
                 tty ? "\r\033[K" : "", double(in - last_in) / dt, double(out - last_out) / dt,
                 counters.rpp.load(), cam.dropped + counters.render_busy + counters.output_busy,
                 cam.dropped, counters.render_busy.load(), focus, lens_state.state.f_number.value,
                 lens_state.state.focal_length_mm.value, lens_state.fresh ? "" : " (stale)",
                 1e-6 * double(counters.latency_ns.load()),
                 counters.camera_lost ? "  CAMERA LOST: placeholder" : "", tty ? "" : "\n");
    std::fflush(options.status);
    last_in = in;
    last_out = out;
    last_ns = now;
  }
  stopping = true;
  capture_thread.join();
  render_thread.join();
  output_thread.join();
  if (tty)
    std::fprintf(options.status, "\n");

  RunSummary summary;
  for (const auto &sink : sinks)
    if (!sink->close()) {
      ++summary.sink_errors;
      if (options.status != nullptr)
        std::fprintf(options.status, "camhead run: %s: %s\n", sink->name().c_str(),
                     sink->status().detail.c_str());
    }
  if (stats != nullptr && std::fclose(stats) != 0)
    throw std::runtime_error(options.stats_file->string() + ": write failed");
  const hal::camera::CameraStatus cam = camera->status();
  summary.frames_in = counters.frames_in;
  summary.frames_out = counters.frames_out;
  summary.camera_dropped = cam.dropped;
  summary.camera_errors = cam.errors;
  summary.camera_reconnects = cam.reconnects;
  summary.render_busy = counters.render_busy;
  summary.output_busy = counters.output_busy;
  summary.render_failed = counters.render_failed;
  summary.placeholders = counters.placeholders;
  summary.repeats = counters.repeats;
  summary.sink_errors += counters.sink_errors;
  summary.seconds = double(base::monotonic_ns() - start_ns) * 1e-9;
  summary.executor = executor_name;
  return summary;
}

} // namespace camhead::pipeline
