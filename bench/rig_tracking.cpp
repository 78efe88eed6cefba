// The marker tracker on the moving simulated rig's own pictures, frame by
// frame and reproducibly (issue 25): `camhead run` on board/sim-moving.json
// films the loop at instants set by when the run started, and tracks what
// the machine has time for; this renders the loop's pictures at fixed
// instants (k / fps on the path's clock) through the same world renderer
// and lens truth as the simulated camera (run/rig_setup.cpp,
// run/trace_lens.h), tracks every one in order as the live source does
// (the lens of its mid-exposure, guided by the poses found before:
// tracker_guides, track_guided), and writes a record that registration_by_blur
// reads like a run's (each frame's tracking time in it too, as track_ms):
//
//   build/bench/rig_tracking board/sim-moving.json m.jsonl [--samples N] [--loops N]
//                            [--pictures FILE]
//   build/bench/registration_by_blur board/sim-moving.json m.jsonl [OUT]
//
// The pictures are kept in FILE (m.jsonl.luma where not given: their luma
// planes, about 60 MB for the bundled loop) and read back by a later run
// of the same board, world and samples, so that a change to the tracker is
// measured on the same pictures in seconds. The tracker gets the lens the camera filmed with (the
// trace as the glass moved), not the lens chain's estimate of it: this measures the tracker alone.
// No still filter: the rig never stands still.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "camhead/base/monotonic_clock.h"
#include "camhead/base/progress_line.h"
#include "camhead/renderer/frame_renderer.h"
#include "config/board.h"
#include "run/lens_camera.h"
#include "run/rig_setup.h"
#include "run/trace_lens.h"
#include "tracking/camera_pose.h"
#include "tracking/luma.h"
#include "tracking/marker_board.h"
#include "tracking/marker_source.h"
#include "tracking/marker_tracker.h"
#include "tracking/pose_timeline.h"
#include "tracking/pose_trace.h"

namespace {

using namespace camhead::pipeline;
namespace renderer = camhead::renderer;

const bool kModuleFound = setenv("CAMHEAD_MARKERS_MODULE", CAMHEAD_BENCH_MARKERS_MODULE, 0) == 0;

std::string contents_of(const std::filesystem::path &file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// What the kept pictures are of, so that pictures of another world are
// never read back: the board, its scene, its path and its lens traces, byte
// for byte (not the files the scene names: textures, meshes).
std::size_t world_digest(const Board &board, const SimCameraConfig &sim) {
  std::string all = contents_of(board.file) + contents_of(*board.scene) + contents_of(*sim.path);
  for (const LensSourceConfig &source : board.lens.sources)
    if (const auto *trace = std::get_if<TraceSourceConfig>(&source.kind))
      all += contents_of(trace->file);
  return std::hash<std::string>{}(all);
}

void write_vec(std::FILE *out, const char *key, const glm::dvec3 &v) {
  std::fprintf(out, "\"%s\":[%.6f,%.6f,%.6f]", key, v.x, v.y, v.z);
}

int run(int argc, char **argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: rig_tracking BOARD.json OUT.jsonl [--samples N] [--loops N] "
                         "[--pictures FILE]\n");
    return 2;
  }
  const Board board = load_board(argv[1]);
  const std::string out_path = argv[2];
  const auto *sim = board.camera ? std::get_if<SimCameraConfig>(&board.camera->kind) : nullptr;
  if (sim == nullptr || !sim->path || !board.pose || board.pose->type != PoseType::marker ||
      !board.scene)
    throw std::runtime_error(std::string(argv[1]) +
                             ": wants a simulated camera with a path, a scene and a marker pose");
  std::uint32_t samples = sim->samples;
  int loops = 2;
  std::string luma_path = out_path + ".luma";
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--samples")
      samples = std::uint32_t(std::stoul(argv[i + 1]));
    else if (flag == "--loops")
      loops = std::stoi(argv[i + 1]);
    else if (flag == "--pictures")
      luma_path = argv[i + 1];
    else
      throw std::runtime_error("unknown option " + flag);
  }
  const PoseTrace path = load_pose_trace(*sim->path);
  const std::optional<TraceLens> lens = TraceLens::of_board(board);
  if (!lens || !lens->loop_period_s())
    throw std::runtime_error(std::string(argv[1]) + ": wants a looped lens trace on the "
                                                    "monotonic clock (the truth)");
  const renderer::Scene scene = load_run_scene(board);
  const renderer::FrameCamera base = base_camera(board, scene);
  // The camera's own format (limited range, as the simulated camera's).
  const camhead::base::VideoFormat format{board.camera->format, board.camera->width,
                                          board.camera->height};
  const std::int64_t interval_ns = std::llround(1e9 / sim->fps);
  const double path_s = double(path.rows().back().t_ns - path.rows().front().t_ns) * 1e-9;
  const int frames = int(std::lround(std::max(path_s, *lens->loop_period_s()) * sim->fps));
  const std::size_t plane = std::size_t(format.width) * std::size_t(format.height);

  // The loop's pictures: read back, or rendered and kept.
  std::vector<std::uint8_t> pictures(plane * std::size_t(frames));
  const std::string stamp = std::string(argv[1]) + " samples " + std::to_string(samples) + " " +
                            std::to_string(frames) + " world " +
                            std::to_string(world_digest(board, *sim)) + "\n";
  bool read_back = false;
  if (std::ifstream in(luma_path, std::ios::binary); in) {
    std::string line;
    std::getline(in, line);
    read_back = line + "\n" == stamp && in.read(reinterpret_cast<char *>(pictures.data()),
                                                std::streamsize(pictures.size()));
  }
  if (!read_back) {
    renderer::Scene world = scene;
    std::erase_if(world.objects, [](const renderer::Object &o) { return !o.real; });
    const auto renderer = renderer::make_cpu_frame_renderer(world, 2);
    std::vector<std::uint8_t> frame(camhead::base::frame_bytes(format)), luma(plane);
    camhead::base::ProgressLine progress("rig_tracking: the loop's pictures", "pictures");
    for (int k = 0; k < frames; ++k) {
      const std::int64_t mid = std::int64_t(k) * interval_ns;
      renderer::FrameRequest request;
      request.camera = lens_camera(placed(base, path.at(mid)), lens->state_at(mid));
      request.rays_per_pixel = samples;
      request.seed = std::uint32_t(mid / 1000) | 1u;
      const renderer::VideoBuffer target{format, frame};
      if (renderer->render(request, {format, {}}, std::span(&target, 1)).status !=
          renderer::FrameStatus::ok)
        throw std::runtime_error("picture " + std::to_string(k) + " did not render");
      copy_luma(format, frame, luma);
      std::copy(luma.begin(), luma.end(),
                pictures.begin() + std::ptrdiff_t(plane * std::size_t(k)));
      progress.update(k + 1, frames);
    }
    progress.finish();
    std::ofstream keep(luma_path, std::ios::binary);
    keep << stamp;
    keep.write(reinterpret_cast<const char *>(pictures.data()), std::streamsize(pictures.size()));
  }

  // Tracked in order, `loops` times round (the first frame has no guide).
  const std::unique_ptr<MarkerTracker> tracker =
      open_marker_tracker(load_marker_board(board.pose->file));
  PoseTimeline found(predicted_pose_params(interval_ns));
  std::FILE *out = std::fopen(out_path.c_str(), "w");
  if (out == nullptr)
    throw std::runtime_error("cannot write " + out_path);
  double track_s = 0.0;
  for (int k = 0; k < frames * loops; ++k) {
    const std::int64_t mid = std::int64_t(k) * interval_ns;
    const camhead::lens_control::LensState state = lens->state_at(mid);
    const LumaImage luma{pictures.data() + plane * std::size_t(k % frames), format.width,
                         format.height, std::ptrdiff_t(format.width), luma_limited_range(format)};
    const std::int64_t start = camhead::base::monotonic_ns();
    const MarkerPose pose =
        track_guided(*tracker, luma, tracker_camera(state, format, board.camera->sensor_width_mm),
                     tracker_guides(found, mid), state.entrance_pupil_offset_mm.value / 1000.0);
    const double frame_s = double(camhead::base::monotonic_ns() - start) * 1e-9;
    track_s += frame_s;
    if (pose.found)
      (void)found.push(mid, pose.pose);
    const CameraPose recorded = pose.found         ? pose.pose
                                : found.size() > 0 ? found.at(mid)->pose
                                                   : CameraPose{};
    std::fprintf(out, "{\"kind\":\"composite\",\"sequence\":%d,\"exposure_mid_ns\":%lld,", k,
                 static_cast<long long>(mid));
    std::fprintf(out, "\"pose_fresh\":%s,\"pose\":{", pose.found ? "true" : "false");
    write_vec(out, "position", recorded.position);
    std::fprintf(out, ",");
    write_vec(out, "forward", recorded.forward());
    std::fprintf(out, ",");
    write_vec(out, "up", recorded.up());
    std::fprintf(out, "},\"markers_seen\":%d,\"pose_found_by\":", pose.markers_seen);
    if (pose.found)
      std::fprintf(out, "\"%s\"",
                   pose.aligned    ? "alignment"
                   : pose.followed ? "corners"
                                   : "markers");
    else
      std::fprintf(out, "null");
    if (pose.found)
      std::fprintf(out, ",\"reprojection_px\":%.4f", pose.reprojection_px);
    else
      std::fprintf(out, ",\"reprojection_px\":null");
    std::fprintf(out, ",\"track_ms\":%.3f}\n", 1e3 * frame_s);
  }
  std::fclose(out);
  std::printf("rig_tracking: %d frames tracked (%d loops of %d), %.1f ms a frame; wrote %s\n",
              frames * loops, loops, frames, 1e3 * track_s / (frames * loops), out_path.c_str());
  return 0;
}

} // namespace

int main(int argc, char **argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "rig_tracking: %s\n", e.what());
    return 1;
  }
}
