// The operator page's files (web/page/), built into the module by
// cmake/embed_files.cmake.
#pragma once

#include <cstddef>

namespace camhead::pipeline::web {

struct EmbeddedFile {
  const char *name; // "index.html"; null ends the table
  const unsigned char *bytes;
  std::size_t size;
};

extern const EmbeddedFile kEmbeddedFiles[];

} // namespace camhead::pipeline::web
