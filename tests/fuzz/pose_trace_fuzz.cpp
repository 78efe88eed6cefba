// libFuzzer target for the pose-trace reader (pipeline/tracking/
// pose_trace.h): any text must be refused with a PoseTraceError or give a
// path of at least two rows, strictly later each, whose pose at any instant
// (before, inside, after and far past it) is finite with a unit rotation.
// Any other exception is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "fuzz_check.h"
#include "tracking/pose_trace.h"

using camhead::fuzz::check;
using namespace camhead::pipeline;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  try {
    const PoseTrace trace = parse_pose_trace(camhead::fuzz::text_of(data, size), "fuzz_path.csv");
    const auto &rows = trace.rows();
    check(rows.size() >= 2);
    for (std::size_t i = 1; i < rows.size(); ++i)
      check(rows[i].t_ns > rows[i - 1].t_ns);
    for (const std::int64_t t :
         {std::int64_t{0}, rows.front().t_ns, (rows.front().t_ns + rows.back().t_ns) / 2,
          rows.back().t_ns, std::int64_t{-1'000'000'000},
          std::numeric_limits<std::int64_t>::max() / 2}) {
      const CameraPose p = trace.at(t);
      check(std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
            std::isfinite(p.position.z));
      check(std::abs(glm::length(p.orientation) - 1.0) < 1e-9);
    }
  } catch (const PoseTraceError &) {
  }
  return 0;
}
