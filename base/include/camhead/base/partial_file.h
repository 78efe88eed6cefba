// A file written as NAME.partial and renamed over NAME when it is complete:
// every file camhead writes (images, profiles, traces, video), so that a
// write that fails half-way (disk full, a size limit, a crash) leaves the
// previous NAME as it was, and a NAME that is a device node, a FIFO or a
// folder is refused rather than replaced. Errors are values ("REASON", the
// caller adds the name), since the file sinks must not throw once open.
//
// Thread safety: none; one sink thread owns it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>

#include <sys/types.h>

namespace camhead::base {

// Why `path` cannot be replaced by a rename: it exists and is not a regular
// file (followed through symbolic links). Empty when it can.
[[nodiscard]] std::string check_replaceable(const std::filesystem::path &path);

class PartialFile {
public:
  // Creates (or empties) PATH.partial after check_replaceable(path); empty
  // with `error` when either fails. A PATH that is a symbolic link stands
  // for the file it points to: that file is replaced, the link stays.
  [[nodiscard]] static std::optional<PartialFile> create(const std::filesystem::path &path,
                                                         std::string &error);

  PartialFile(PartialFile &&other) noexcept;
  PartialFile &operator=(PartialFile &&) = delete;
  PartialFile(const PartialFile &) = delete;
  ~PartialFile(); // removes the partial file unless committed

  // All of `bytes`, or false with `error`; a failed write may have left part
  // of them (see truncate).
  [[nodiscard]] bool write(std::span<const std::uint8_t> bytes, std::string &error);

  // Cuts the file back to `size` bytes, dropping a frame that failed half-way.
  [[nodiscard]] bool truncate(off_t size, std::string &error);

  [[nodiscard]] off_t size() const { return size_; }

  // Flushes (fsync when `durable`), closes and renames over PATH.
  [[nodiscard]] bool commit(bool durable, std::string &error);

  // Closes and removes the partial file.
  void discard();

  // Closes and leaves the partial file where it is, unrenamed: what a crash
  // would leave, for a recording that was not finished.
  void abandon();

  [[nodiscard]] const std::filesystem::path &partial_path() const { return partial_; }

private:
  PartialFile(std::filesystem::path path, std::filesystem::path partial, int fd)
      : path_(std::move(path)), partial_(std::move(partial)), fd_(fd) {}

  std::filesystem::path path_;
  std::filesystem::path partial_;
  int fd_ = -1;
  off_t size_ = 0;
};

} // namespace camhead::base
