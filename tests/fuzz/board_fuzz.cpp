// libFuzzer target for the board-file reader (pipeline/config/board.h) and what
// `camhead run` builds from a board before it opens a device: the output
// URIs, the check of every path the run reads and writes against the others
// (run_paths.h; it only looks at paths, with stat()), the camera's size,
// the frame budget of its render section and the pose's view. Any text must be refused with the
// error of the step that read it, or give a rig whose invariants hold; anything else is a finding.
// Nothing is opened for writing and no device is started.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "camhead/renderer/frame_budget.h"
#include "camhead/renderer/scene.h"
#include "config/board.h"
#include "fuzz_check.h"
#include "run/output_uri.h"
#include "run/run_paths.h"

namespace {

using namespace camhead;

bool finite(glm::vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// The camera frame make_frame_params() builds from a pose: a pose the board
// reader lets through must give one without a NaN or a zero axis.
void check_pose(const pipeline::PoseConfig &pose) {
  const pipeline::PoseVectors v = pipeline::pose_vectors(pose);
  const glm::vec3 forward = glm::normalize(v.look_at - v.position);
  const glm::vec3 right = glm::normalize(glm::cross(forward, v.up));
  fuzz::check(finite(forward) && finite(right) && glm::length(right) > 0.5f);
}

void build_rig(const pipeline::Board &board) {
  const std::vector<pipeline::OutputSpec> outputs = pipeline::parse_output_uris(board.outputs);
  renderer::Scene scene;
  if (board.scene)
    scene.source = *board.scene;
  std::vector<pipeline::RunPath> paths = pipeline::run_inputs(board, scene);
  for (pipeline::RunPath &output : pipeline::run_outputs(outputs))
    paths.push_back(std::move(output));
  pipeline::check_run_paths(paths);
  if (board.camera) {
    const auto &c = *board.camera;
    fuzz::check(c.width >= 2 && c.height >= 2 && c.width % 2 == 0 && c.height % 2 == 0 &&
                std::int64_t(c.width) * c.height <= std::int64_t(1) << 25);
    // The render section as the render thread takes it: a budget its
    // constructor accepts (it throws on a range the reader let through).
    const auto *sim = std::get_if<pipeline::SimCameraConfig>(&c.kind);
    renderer::FrameBudgetSettings settings;
    settings.target_s = 1.0 / (sim != nullptr ? sim->fps : 25.0);
    settings.min_rpp = board.render.min_rays_per_pixel;
    settings.max_rpp = board.render.max_rays_per_pixel;
    const renderer::FrameBudget budget(settings);
    fuzz::check(budget.rpp() >= settings.min_rpp && budget.rpp() <= settings.max_rpp);
  }
  if (board.pose)
    check_pose(*board.pose);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  try {
    build_rig(pipeline::parse_board(fuzz::text_of(data, size), "/nonexistent/fuzz_board.json"));
  } catch (const pipeline::BoardError &) {
  } catch (const pipeline::OutputError &) {
  } catch (const pipeline::RunPathError &) {
  }
  return 0;
}
