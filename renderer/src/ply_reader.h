// PLY has no header-only reader in Debian, so a small one lives here: it
// reads what mesh exporters write (ascii and both binary byte orders, any extra
// elements and properties) and treats every count and index in the file as
// untrusted. Private to the renderer.
#pragma once

#include <filesystem>

#include "camhead/renderer/scene.h"

namespace camhead::renderer::detail {

// The mesh as the file `path` has it (its bytes in `text`); parse_mesh()
// validates it. Throws MeshError.
TriangleMesh parse_ply(const std::filesystem::path &path, const std::string &text);

} // namespace camhead::renderer::detail
