// What `camhead run` opens before the first frame, from a board: the scene at
// the camera's size, the pose, the executor, the frame renderer, the camera
// (the simulated one filming the scene's real objects) and the outputs.
// Everything here throws, naming the board field, file or device at fault;
// nothing after it does.
#pragma once

#include <cstdint>
#include <memory>

#include "camhead/hal/camera/camera_source.h"
#include "camhead/hal/output/frame_sink.h"
#include "camhead/renderer/frame_camera.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/scene.h"
#include "config/board.h"
#include "lens_hub.h"
#include "output_uri.h"

namespace camhead::pipeline {

class MarkerPoseSource;

// The board's scene, rendered at the camera's size, without its plate.
[[nodiscard]] renderer::Scene load_run_scene(const Board &board);

// The scene's camera moved to the board's pose, on the camera's sensor.
[[nodiscard]] renderer::FrameCamera base_camera(const Board &board, const renderer::Scene &scene);

// The live frame's renderer. `automatic` is a hardware GPU where there is
// one that takes the scene, else the CPU reference: on the same cores it
// renders a live frame over the influence region as fast as lavapipe,
// without lavapipe's kernel compiles at start (bench/RESULTS.md, "The live
// frame on lavapipe, again"). A GPU asked for by name that cannot take the
// scene is an error (GpuError, or base::ConfigError on the board's
// camera.width); `automatic` says why it fell back.
[[nodiscard]] std::unique_ptr<renderer::FrameRenderer>
make_renderer(const Board &board, Executor wanted, const renderer::Scene &scene, int threads);

// How much a run is asked for (0: no limit).
struct RunLength {
  std::uint64_t frames = 0;
  double duration_s = 0.0;
};

// The board's camera. The simulated one renders the scene's real objects
// through the lens at each exposure (trace_lens.h, or `lens`) with Vulkan,
// or without a Vulkan device on `threads` of the CPU reference. Where its
// lens (and path) loop on its frame clock and its cache keeps the whole
// loop, it renders the loop before it opens, with a progress line, so that
// its frames come at its rate from the first (what a real camera does;
// without this its first loop is slower, and a video of it plays too
// fast), unless `length` asks for less than a loop.
[[nodiscard]] std::unique_ptr<hal::camera::CameraSource>
open_camera(const Board &board, const renderer::Scene &scene, const renderer::FrameCamera &pose,
            const LensHub &lens, int threads, const RunLength &length);

// A marker pose's tracker for frames of `format` (its board loaded, the
// OpenCV module opened: throws MarkerBoardError, MarkerModuleError); null
// for any other pose. `every_frame`: a take composited offline;
// `lens_wait_ns`: how long a frame's tracking waits for its lens;
// `fps`: the camera's rate (marker_source.h).
[[nodiscard]] std::unique_ptr<MarkerPoseSource>
open_marker_source(const Board &board, const base::VideoFormat &format,
                   const renderer::FrameCamera &base, const LensHub &lens, bool every_frame,
                   std::int64_t lens_wait_ns, double fps);

// Opens the sink at `width` x `height`, `fps` frames a second (for the
// formats that carry a rate). Throws OutputError (or the backend's error,
// which names the file or device).
[[nodiscard]] std::unique_ptr<hal::output::FrameSink> open_output(const OutputSpec &spec, int width,
                                                                  int height, double fps);

// The camera's rate, 25 where it does not say.
[[nodiscard]] double camera_fps(const hal::camera::CameraSource &camera);

} // namespace camhead::pipeline
