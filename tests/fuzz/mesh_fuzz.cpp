// libFuzzer target for the OBJ and PLY readers (renderer/mesh_io.h), built
// twice: MESH_EXTENSION picks the format. Any text must be refused with a
// MeshError or read into a mesh whose every triangle names a finite vertex;
// any other exception, crash or undefined behaviour is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "camhead/renderer/mesh_io.h"
#include "fuzz_check.h"

using camhead::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  try {
    const camhead::renderer::TriangleMesh mesh =
        camhead::renderer::parse_mesh(camhead::fuzz::text_of(data, size), "fuzz" MESH_EXTENSION);
    check(!mesh.triangles.empty());
    for (const auto &p : mesh.positions)
      check(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    for (const auto &t : mesh.triangles)
      check(t.x < mesh.positions.size() && t.y < mesh.positions.size() &&
            t.z < mesh.positions.size());
  } catch (const camhead::renderer::MeshError &) {
  }
  return 0;
}
