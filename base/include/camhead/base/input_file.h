// The one way camhead reads a whole input file (scenes, meshes, images, lens
// files, boards, PNG frames). Every reader bounds what it takes: a path can
// name /dev/zero, or a file larger than anything the reader could use, and
// neither may become an allocation the machine cannot give
// (docs/input-errors.md).
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace camhead::base {

// The whole of `path`, at most `max_bytes` of it. Folders are refused (Linux
// opens them and then reads nothing); pipes and devices are read like files,
// up to the bound. Empty with `error` ("cannot be opened: REASON", "is a
// folder, not a file", "is larger than N MiB", "cannot be read: REASON").
[[nodiscard]] std::optional<std::string> read_input_file(const std::filesystem::path &path,
                                                         std::size_t max_bytes, std::string &error);

// The same into `bytes`, whose capacity is kept between calls (a PNG
// sequence reads a file a frame). False with `error`.
[[nodiscard]] bool read_input_file(const std::filesystem::path &path, std::size_t max_bytes,
                                   std::vector<unsigned char> &bytes, std::string &error);

} // namespace camhead::base
