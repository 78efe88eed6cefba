// See frame_setup.h.
#include "frame_setup.h"

#include <chrono>
#include <thread>
#include <utility>

#include "rig_setup.h"

namespace camhead::pipeline {

std::unique_ptr<FrameSetup> load_frame_setup(Board board) {
  auto setup = std::make_unique<FrameSetup>();
  setup->scene = load_run_scene(board);
  setup->base_camera = base_camera(board, setup->scene);
  setup->rest_pose = pose_of(setup->base_camera);
  setup->board = std::move(board);
  return setup;
}

renderer::FrameBudgetSettings frame_budget_settings(const RenderConfig &render, double fps) {
  renderer::FrameBudgetSettings settings;
  settings.target_s = 1.0 / fps;
  settings.min_rpp = render.min_rays_per_pixel;
  settings.max_rpp = render.max_rays_per_pixel;
  return settings;
}

renderer::FrameRequest setup_request(const FrameSetup &setup, bool influence_region) {
  renderer::FrameRequest request;
  request.camera = setup.base_camera;
  request.adaptive = setup.board.render.adaptive;
  request.influence_region = influence_region;
  request.accumulation = setup.board.render.accumulation;
  return request;
}

std::unique_ptr<FrameSetup> SetupHandover::offer(std::unique_ptr<FrameSetup> next,
                                                 const std::function<bool()> &stop, bool &taken) {
  {
    const std::lock_guard lock(mutex_);
    offered_ = std::move(next);
    waiting_ = true;
  }
  while (waiting_ && !stop())
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const std::lock_guard lock(mutex_);
  taken = !waiting_;
  waiting_ = false;
  return std::move(offered_);
}

bool SetupHandover::take(std::unique_ptr<FrameSetup> &current) {
  if (!waiting_.load(std::memory_order_acquire))
    return false;
  const std::lock_guard lock(mutex_);
  if (!waiting_)
    return false; // withdrawn: the run is stopping
  current.swap(offered_);
  waiting_ = false;
  return true;
}

} // namespace camhead::pipeline
