// See partial_file.h.
#include "camhead/base/partial_file.h"

#include <cerrno>
#include <cstring>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace camhead::base {
namespace {

std::string errno_text() {
  return std::strerror(errno);
}

std::string_view kind_of(mode_t mode) {
  if (S_ISDIR(mode))
    return "a folder";
  if (S_ISCHR(mode) || S_ISBLK(mode))
    return "a device node";
  if (S_ISFIFO(mode))
    return "a FIFO";
  if (S_ISSOCK(mode))
    return "a socket";
  return "not a regular file";
}

} // namespace

std::string check_replaceable(const std::filesystem::path &path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return errno == ENOENT ? std::string() : "cannot check it: " + errno_text();
  if (S_ISREG(st.st_mode))
    return {};
  return "exists and is " + std::string(kind_of(st.st_mode)) +
         ", not a regular file: refusing to replace it";
}

std::optional<PartialFile> PartialFile::create(const std::filesystem::path &path,
                                               std::string &error) {
  // Through a link to the file it names, which is replaced with the link
  // kept: renaming over the link itself would turn /dev/stdout, or a link
  // into a take library, into a plain file.
  std::filesystem::path target = path;
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode)) {
    std::error_code ec;
    target = std::filesystem::canonical(path, ec);
    if (ec) {
      error = "is a symbolic link that cannot be followed: " + ec.message();
      return std::nullopt;
    }
  }
  error = check_replaceable(target);
  if (!error.empty())
    return std::nullopt;
  std::filesystem::path partial = target;
  partial += ".partial";
  // A stray partial file from a crash is ours to overwrite; anything else
  // under that name is not.
  if (::lstat(partial.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    error = partial.string() + " exists and is " + std::string(kind_of(st.st_mode));
    return std::nullopt;
  }
  const int fd =
      ::open(partial.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0666);
  if (fd < 0) {
    error = "cannot create " + partial.string() + ": " + errno_text();
    return std::nullopt;
  }
  return PartialFile(std::move(target), std::move(partial), fd);
}

PartialFile::PartialFile(PartialFile &&other) noexcept
    : path_(std::move(other.path_)), partial_(std::move(other.partial_)), fd_(other.fd_),
      size_(other.size_) {
  other.fd_ = -1;
  other.partial_.clear();
}

PartialFile::~PartialFile() {
  discard();
}

bool PartialFile::write(std::span<const std::uint8_t> bytes, std::string &error) {
  if (fd_ < 0) {
    error = "the file is closed";
    return false;
  }
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n < 0) {
      if (errno == EINTR)
        continue;
      error = "write to " + partial_.string() + ": " + errno_text();
      return false;
    }
    size_ += n;
    bytes = bytes.subspan(static_cast<std::size_t>(n));
  }
  return true;
}

bool PartialFile::truncate(off_t size, std::string &error) {
  if (fd_ < 0 || ::ftruncate(fd_, size) != 0 || ::lseek(fd_, size, SEEK_SET) != size) {
    error = "cannot cut " + partial_.string() + " back to its last whole frame: " + errno_text();
    return false;
  }
  size_ = size;
  return true;
}

bool PartialFile::commit(bool durable, std::string &error) {
  if (fd_ < 0) {
    error = "the file is closed";
    return false;
  }
  // Synced before the rename, or a crash could leave PATH renamed but empty.
  const bool synced = !durable || ::fsync(fd_) == 0;
  const int sync_errno = errno;
  const bool closed = ::close(fd_) == 0;
  fd_ = -1;
  if (!synced || !closed) {
    errno = synced ? errno : sync_errno;
    error = "cannot finish " + partial_.string() + ": " + errno_text();
    discard();
    return false;
  }
  // Checked again: something may have appeared under PATH since the open.
  error = check_replaceable(path_);
  if (!error.empty()) {
    discard();
    return false;
  }
  if (::rename(partial_.c_str(), path_.c_str()) != 0) {
    error = "cannot rename " + partial_.string() + " into place: " + errno_text();
    discard();
    return false;
  }
  partial_.clear();
  return true;
}

void PartialFile::abandon() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  partial_.clear();
}

void PartialFile::discard() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (!partial_.empty()) {
    ::unlink(partial_.c_str());
    partial_.clear();
  }
}

} // namespace camhead::base
