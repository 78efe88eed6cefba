#include "rig_setup.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "camhead/base/config_error.h"
#include "camhead/base/overloaded.h"
#include "camhead/base/progress_line.h"
#include "camhead/hal/camera/file/file_camera.h"
#include "camhead/hal/camera/libcamera/libcamera_camera.h"
#include "camhead/hal/camera/sim/simulated_camera.h"
#include "camhead/hal/camera/v4l2/v4l2_camera.h"
#include "camhead/hal/output/drm/drm_sink.h"
#include "camhead/hal/output/file/file_sink.h"
#include "camhead/hal/output/null/null_sink.h"
#include "camhead/hal/output/v4l2/v4l2_loopback_sink.h"
#include "camhead/renderer/gpu_tracer.h"
#include "camhead/renderer/scene_loader.h"
#include "lens_camera.h"
#include "trace_lens.h"
#include "tracking/camera_pose.h"
#include "tracking/marker_source.h"
#include "tracking/pose_trace.h"

namespace camhead::pipeline {

using hal::camera::CameraSource;

namespace {

renderer::Scene real_world_of(renderer::Scene scene) {
  std::erase_if(scene.objects, [](const renderer::Object &o) { return !o.real; });
  return scene;
}

// The simulated world's pictures already rendered, by the exact camera they
// were rendered for. Rendering the world costs as much as a frame of the
// pipeline (more: every pixel is traced); a looped trace on the camera's
// frame clock repeats its lens states exactly, so from its second loop on
// the simulated camera costs a copy and the pipeline has the machine to
// itself. Filled until `capacity` bytes, then only read.
class WorldPictures {
public:
  explicit WorldPictures(std::size_t capacity) : capacity_(capacity) {}

  // How many pictures of `bytes` each it keeps at most.
  [[nodiscard]] std::size_t holds(std::size_t bytes) const { return capacity_ / bytes; }

  bool copy(const renderer::FrameCamera &camera, std::span<std::uint8_t> out) {
    const std::lock_guard lock(mutex_);
    const auto it = pictures_.find(key_of(camera));
    if (it == pictures_.end() || it->second.size() != out.size())
      return false;
    std::copy(it->second.begin(), it->second.end(), out.begin());
    return true;
  }

  void keep(const renderer::FrameCamera &camera, std::span<const std::uint8_t> picture) {
    const std::lock_guard lock(mutex_);
    if (used_ + picture.size() > capacity_)
      return;
    if (pictures_.try_emplace(key_of(camera), picture.begin(), picture.end()).second)
      used_ += picture.size();
  }

private:
  using Key = std::array<std::uint32_t, 23>;

  // Every field's bits: two cameras share a picture only if they are equal.
  static Key key_of(const renderer::FrameCamera &c) {
    static_assert(sizeof(renderer::FrameCamera) == sizeof(Key), "a FrameCamera field is not keyed");
    const float fields[23] = {c.position.x,
                              c.position.y,
                              c.position.z,
                              c.look_at.x,
                              c.look_at.y,
                              c.look_at.z,
                              c.up.x,
                              c.up.y,
                              c.up.z,
                              c.focus_distance_m,
                              c.f_number,
                              c.focal_length_mm,
                              c.projection_focal_length_mm,
                              c.sensor_width_mm,
                              c.entrance_pupil_offset_m,
                              c.lens_model.principal_point.x,
                              c.lens_model.principal_point.y,
                              c.lens_model.fy_over_fx,
                              c.lens_model.k1,
                              c.lens_model.k2,
                              c.lens_model.k3,
                              c.lens_model.p1,
                              c.lens_model.p2};
    Key key;
    std::memcpy(key.data(), fields, sizeof fields);
    return key;
  }

  std::mutex mutex_;
  std::map<Key, std::vector<std::uint8_t>> pictures_;
  std::size_t capacity_;
  std::size_t used_ = 0;
};

// The simulated world's renderer, whatever executor the pipeline has: the
// camera stands in for hardware, not for the pipeline's work. Its frames are
// whole (every pixel at the camera's samples), which the Vulkan tracer
// renders faster than the CPU reference even on lavapipe; with the CPU
// reference compositing, the rig's first half minute went from 5-6 to 15
// frames a second out (bench/RESULTS.md, "lavapipe on the AMD EPYC").
// Without a Vulkan device, or for a frame the Vulkan one does not take (a
// width that is not a multiple of 4), the CPU reference on `threads`, and
// the user is told why: it makes the rig's first loop slower.
std::shared_ptr<renderer::FrameRenderer> make_world_renderer(const renderer::Scene &world,
                                                             int threads) {
  std::string why;
  try {
    return renderer::make_gpu_frame_renderer(world);
  } catch (const renderer::GpuError &e) {
    why = e.what();
  } catch (const std::invalid_argument &e) {
    why = e.what();
  }
  std::fprintf(stderr,
               "camhead run: the simulated camera renders its world on the CPU reference, not "
               "Vulkan: %s\n",
               why.c_str());
  return renderer::make_cpu_frame_renderer(world, threads);
}

// The frames of the simulated world's loop (its lens's, and its path's
// where it has one: together they repeat only where one is a whole number
// of the other), when they repeat on the camera's frame clock and the
// cache (WorldPictures) keeps them all: then the camera can render them
// once and replay them. Otherwise empty, and the user is told why its
// world is rendered for every frame, or for the frames the cache cannot
// keep.
std::optional<long> world_loop_frames(const SimCameraConfig &sim, const base::VideoFormat &format,
                                      const std::optional<TraceLens> &truth,
                                      const std::optional<PoseTrace> &path,
                                      const WorldPictures &cache) {
  if (!truth || !truth->loop_period_s())
    return std::nullopt;
  double period_s = *truth->loop_period_s();
  if (path) {
    const double path_s = double(path->rows().back().t_ns - path->rows().front().t_ns) * 1e-9;
    const double longer = std::max(period_s, path_s), shorter = std::min(period_s, path_s);
    const double ratio = longer / shorter;
    if (std::abs(ratio - std::round(ratio)) > 1e-6) {
      std::fprintf(stderr,
                   "camhead run: the simulated camera renders its world for every frame: its "
                   "path's loop (%.3f s) and its lens's (%.3f s) do not repeat together\n",
                   path_s, period_s);
      return std::nullopt;
    }
    period_s = longer;
  }
  const double frames = period_s * sim.fps;
  const long states = std::lround(frames);
  if (sim.cache_mb == 0 || states < 1)
    return std::nullopt;
  if (std::abs(frames - double(states)) > 1e-6) {
    std::fprintf(stderr,
                 "camhead run: the simulated camera renders its world for every frame: its "
                 "lens loop (%.3f s) is not a whole number of its frames (%.3f at %g fps), so "
                 "its frames meet the loop at new instants each time round\n",
                 period_s, frames, sim.fps);
    return std::nullopt;
  }
  const std::size_t picture = base::frame_bytes(format);
  const long kept = long(std::min<std::size_t>(std::size_t(states), cache.holds(picture)));
  if (kept < states) {
    std::fprintf(stderr,
                 "camhead run: the simulated camera renders its world anew for each of the %ld "
                 "%s of its %.1f s loop; it keeps %ld of them in camera.cache_mb = %u and "
                 "renders the rest every loop; %zu would keep them all (where a picture takes "
                 "longer than a frame, it delivers fewer than %g frames a second, counted as "
                 "camera drops)\n",
                 states, path ? "poses and lens states" : "lens states", period_s, kept,
                 sim.cache_mb, (std::size_t(states) * picture + (1u << 20) - 1) >> 20, sim.fps);
    return std::nullopt;
  }
  return states;
}

// The simulated camera's picture: the scene's real objects through the lens
// at each exposure's middle, rendered by its own frame renderer, with a new
// noise pattern every frame as a sensor has. The lens is the physical truth
// where the board's trace gives it (trace_lens.h), else what the lens chain
// says. It films from its path where it has one (the physical truth of a
// moving rig), else from the board's pose: a tracker's moves it (the
// simulated world is where the tracker says the camera is).
std::unique_ptr<CameraSource> open_sim_camera(const SimCameraConfig &sim,
                                              const base::VideoFormat &format,
                                              const renderer::Scene &scene,
                                              const renderer::FrameCamera &pose,
                                              const LensHub &lens, std::optional<TraceLens> truth,
                                              int threads, const RunLength &length) {
  auto world = make_world_renderer(real_world_of(scene), threads);
  hal::camera::SimulatedCameraOptions options;
  options.format = format;
  options.fps = sim.fps;
  options.disconnect_after_frames = sim.disconnect_after_frames;
  options.disconnect_s = sim.disconnect_s;
  options.disconnect_silently = sim.disconnect_silently;
  options.realtime = sim.realtime;
  const std::uint32_t samples = sim.samples;
  auto cache = std::make_shared<WorldPictures>(std::size_t(sim.cache_mb) << 20);
  std::optional<PoseTrace> path;
  if (sim.path)
    path = load_pose_trace(*sim.path);
  // A world the tracker moves does not loop; one not filmed in real time
  // has no clock to keep, so nothing to render ahead.
  const std::optional<long> loop = !sim.realtime || (lens.tracks_pose() && !path)
                                       ? std::nullopt
                                       : world_loop_frames(sim, format, truth, path, *cache);
  if (loop) {
    const double loop_s = double(*loop) / sim.fps;
    const char *states = path ? "poses and lens states" : "lens states";
    if ((length.frames > 0 && length.frames < std::uint64_t(*loop)) ||
        (length.duration_s > 0.0 && length.duration_s < loop_s)) {
      // A run shorter than the loop: rendering it all first would cost more.
      std::fprintf(stderr,
                   "camhead run: the simulated camera renders its world anew for each of the "
                   "%ld %s of its %.1f s loop, then replays them; until then, where a picture "
                   "takes longer than a frame to render, it delivers fewer than %g frames a "
                   "second (counted as camera drops)\n",
                   *loop, states, loop_s, sim.fps);
    } else {
      std::fprintf(stderr,
                   "camhead run: the simulated camera renders its world for each of the %ld %s "
                   "of its %.1f s loop before it starts, then replays them: its frames come at "
                   "%g a second from the first\n",
                   *loop, states, loop_s, sim.fps);
      options.warm_up_frames = std::uint64_t(*loop);
      auto progress =
          std::make_shared<base::ProgressLine>("camhead run: the simulated world", "pictures");
      options.warm_up_progress = [progress](std::uint64_t drawn, std::uint64_t of) {
        progress->update(int(drawn), int(of));
        if (drawn == of)
          progress->finish();
      };
    }
  }
  auto generator = [world, cache, format, pose, rest = pose_of(pose), samples, &lens,
                    truth = std::move(truth),
                    path = std::move(path)](std::int64_t start_ns, std::int64_t exposure_ns,
                                            std::span<std::uint8_t> out) {
    const std::int64_t mid = start_ns + exposure_ns / 2;
    const renderer::FrameCamera posed = path ? placed(pose, path->at(mid))
                                        : lens.tracks_pose()
                                            ? placed(pose, lens.pose_at(mid, rest).pose)
                                            : pose;
    renderer::FrameRequest request;
    request.camera = lens_camera(posed, truth ? truth->state_at(mid) : lens.state_at(mid).state);
    if (cache->copy(request.camera, out))
      return;
    request.rays_per_pixel = samples;
    request.seed = std::uint32_t(start_ns / 1000) | 1u;
    const renderer::VideoBuffer target{format, out};
    if (world->render(request, {format, {}}, std::span(&target, 1)).status ==
        renderer::FrameStatus::ok)
      cache->keep(request.camera, out);
  };
  return hal::camera::open_simulated_camera(options, std::move(generator));
}

} // namespace

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
    const PoseVectors v = pose_vectors(*board.pose);
    camera.position = v.position;
    camera.look_at = v.look_at;
    camera.up = v.up;
  }
  camera.sensor_width_mm = float(board.camera->sensor_width_mm);
  return camera;
}

namespace {

bool has_hardware_gpu() {
  try {
    for (const renderer::GpuDeviceInfo &device : renderer::list_gpu_devices())
      if (device.type == "discrete" || device.type == "integrated")
        return true;
  } catch (const std::exception &) {
    // No Vulkan at all.
  }
  return false;
}

} // namespace

std::unique_ptr<renderer::FrameRenderer> make_renderer(const Board &board, Executor wanted,
                                                       const renderer::Scene &scene, int threads) {
  // The GPU video kernels work in blocks of 4 x 2 pixels (video_encode.comp).
  const bool gpu_size = board.camera->width % 4 == 0;
  if (wanted == Executor::gpu) {
    if (!gpu_size)
      throw base::ConfigError(board.file.string(), "camera.width",
                              std::to_string(board.camera->width) +
                                  " is not a multiple of 4, which the GPU's video kernels need "
                                  "(--executor cpu renders it)");
    return renderer::make_gpu_frame_renderer(scene);
  }
  if (wanted == Executor::automatic && has_hardware_gpu()) {
    if (!gpu_size)
      std::fprintf(stderr,
                   "camhead run: the CPU reference renders, not Vulkan: camera.width %d is not a "
                   "multiple of 4, which the GPU's video kernels need\n",
                   board.camera->width);
    else
      try {
        return renderer::make_gpu_frame_renderer(scene);
      } catch (const renderer::GpuError &e) {
        std::fprintf(stderr, "camhead run: the CPU reference renders, not Vulkan: %s\n", e.what());
      }
  }
  return renderer::make_cpu_frame_renderer(scene, threads);
}

std::unique_ptr<CameraSource> open_camera(const Board &board, const renderer::Scene &scene,
                                          const renderer::FrameCamera &pose, const LensHub &lens,
                                          int threads, const RunLength &length) {
  const CameraConfig &c = *board.camera;
  // One opener per kind of camera: a kind without one does not compile.
  return std::visit(
      base::Overloaded{[&](const SimCameraConfig &sim) {
                         base::VideoFormat format;
                         format.pixel = c.format;
                         format.width = c.width;
                         format.height = c.height;
                         return open_sim_camera(sim, format, scene, pose, lens,
                                                TraceLens::of_board(board), threads, length);
                       },
                       [&](const V4l2CameraConfig &v4l2) {
                         return hal::camera::open_v4l2_camera({.device = v4l2.device,
                                                               .format = c.format,
                                                               .width = c.width,
                                                               .height = c.height,
                                                               .fps = v4l2.fps,
                                                               .buffers = v4l2.buffers,
                                                               .mjpeg = v4l2.mjpeg});
                       },
                       [&](const LibcameraCameraConfig &libcamera) {
                         return hal::camera::open_libcamera_camera(
                             {.camera_id = libcamera.camera_id,
                              .format = c.format,
                              .width = c.width,
                              .height = c.height,
                              .buffers = libcamera.buffers});
                       },
                       [&](const FileCameraConfig &file) {
                         // The board's size is checked against the take's header before
                         // anything of the take's size is made.
                         return hal::camera::open_file_camera({.path = file.path,
                                                               .loop = file.loop,
                                                               .realtime = file.realtime,
                                                               .fps = 0.0,
                                                               .width = c.width,
                                                               .height = c.height});
                       }},
      c.kind);
}

std::unique_ptr<hal::output::FrameSink> open_output(const OutputSpec &spec, int width, int height,
                                                    double fps) {
  base::VideoFormat format;
  format.pixel = spec.format;
  format.width = width;
  format.height = height;
  switch (spec.kind) {
  case OutputKind::null:
    return hal::output::open_null_sink(format);
  case OutputKind::y4m:
    return hal::output::open_y4m_sink(spec.target, format, fps);
  case OutputKind::png:
    return hal::output::open_png_sequence_sink(spec.target, format);
  case OutputKind::v4l2:
    return hal::output::open_v4l2_loopback_sink(spec.target, format, fps);
  case OutputKind::drm:
    return hal::output::open_drm_sink({.card = spec.target,
                                       .connector = spec.connector,
                                       .width = width,
                                       .height = height,
                                       .mode = spec.mode});
  }
  throw OutputError(spec.uri, "unknown output kind");
}

std::unique_ptr<MarkerPoseSource> open_marker_source(const Board &board,
                                                     const base::VideoFormat &format,
                                                     const renderer::FrameCamera &base,
                                                     const LensHub &lens, bool every_frame,
                                                     std::int64_t lens_wait_ns, double fps) {
  if (!board.pose || board.pose->type != PoseType::marker)
    return nullptr;
  return std::make_unique<MarkerPoseSource>(load_marker_board(board.pose->file), format, base, lens,
                                            every_frame, lens_wait_ns, std::llround(1e9 / fps));
}

double camera_fps(const CameraSource &camera) {
  const std::int64_t interval = camera.frame_interval_ns();
  return interval > 0 ? 1e9 / double(interval) : 25.0;
}

} // namespace camhead::pipeline
