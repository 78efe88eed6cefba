// What the live pipeline renders a frame with, made from a board: the scene,
// the camera at the board's pose, the render settings and the renderer made
// for them. A reload (board_reload.h) makes a whole new one beside the running
// one and hands it to the render thread between two frames (SetupHandover),
// so no output waits for a scene to load or a kernel to compile.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>

#include "camhead/renderer/frame_budget.h"
#include "camhead/renderer/frame_camera.h"
#include "camhead/renderer/frame_renderer.h"
#include "camhead/renderer/scene.h"
#include "config/board.h"
#include "tracking/camera_pose.h"

namespace camhead::pipeline {

struct FrameSetup {
  Board board;
  renderer::Scene scene; // at the camera's size, without its plate
  // The scene's camera at the board's static pose, on the camera's sensor;
  // a tracker's pose replaces its place frame by frame.
  renderer::FrameCamera base_camera;
  CameraPose rest_pose;
  std::unique_ptr<renderer::FrameRenderer> renderer;
  std::uint64_t generation = 0; // 0 as the run started, then one more for each reload
};

// Everything but the renderer, which the caller makes for its executor and
// prepares for its formats. Throws naming the file at fault (the scene's
// SceneError).
[[nodiscard]] std::unique_ptr<FrameSetup> load_frame_setup(Board board);

// The frame budget of the board's render settings for a camera of `fps`
// frames a second (the board reader has checked what FrameBudget checks).
[[nodiscard]] renderer::FrameBudgetSettings frame_budget_settings(const RenderConfig &render,
                                                                  double fps);

// A frame's request as the setup makes it, before the frame's lens, pose,
// rays and seed: `influence_region` as RunOptions says.
[[nodiscard]] renderer::FrameRequest setup_request(const FrameSetup &setup, bool influence_region);

// A new setup from a reload thread to the render thread. The render thread
// only swaps two pointers between frames (nothing is made or freed in its
// loop, and its lock is held only for the other side's swap); what it
// replaced goes back to the reload thread to free
// (RunAllocations.AReloadAllocatesNothingInTheFrameLoop holds it).
//
// Thread safety: offer() from one thread, take() from another.
class SetupHandover {
public:
  // Offers `next` and waits (polling every few ms) until the render thread
  // has taken it, or `stop()` says the run is over. Returns the setup to
  // free: the one replaced, or `next` itself if it was never taken
  // (`taken` says which).
  std::unique_ptr<FrameSetup> offer(std::unique_ptr<FrameSetup> next,
                                    const std::function<bool()> &stop, bool &taken);
  // Render thread, before each frame: puts an offered setup in `current`'s
  // place. Returns whether it did.
  bool take(std::unique_ptr<FrameSetup> &current);

private:
  std::mutex mutex_;
  std::unique_ptr<FrameSetup> offered_;
  std::atomic<bool> waiting_{false}; // offered_ holds a setup not yet taken
};

} // namespace camhead::pipeline
