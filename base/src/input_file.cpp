#include "camhead/base/input_file.h"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <system_error>

#include <sys/stat.h>

namespace camhead::base {
namespace {

struct FileCloser {
  void operator()(std::FILE *file) const { std::fclose(file); }
};

// Rounded down, in the largest unit that keeps a whole number above 0.
std::string in_units(std::size_t bytes) {
  if (bytes >= (std::size_t(1) << 30))
    return std::to_string(bytes >> 30) + " GiB";
  if (bytes >= (std::size_t(1) << 20))
    return std::to_string(bytes >> 20) + " MiB";
  if (bytes >= 1024)
    return std::to_string(bytes >> 10) + " KiB";
  return std::to_string(bytes) + " bytes";
}

// Reads in chunks rather than by the size the file reports: a device or a
// pipe reports none, and a file can grow while it is read. A regular file
// over the bound is refused unread.
template <typename Bytes>
bool read_bounded(const std::filesystem::path &path, std::size_t max_bytes, Bytes &out,
                  std::string &error) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    error = "is a folder, not a file";
    return false;
  }
  const std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rbe"));
  if (!file) {
    error = std::string("cannot be opened: ") + std::strerror(errno);
    return false;
  }
  out.clear();
  struct stat st {};
  if (::fstat(::fileno(file.get()), &st) == 0 && S_ISREG(st.st_mode)) {
    if (std::uintmax_t(st.st_size) > max_bytes) {
      error = "is larger than " + in_units(max_bytes);
      return false;
    }
    out.reserve(std::size_t(st.st_size));
  }
  char chunk[65536];
  std::size_t got = 0;
  while ((got = std::fread(chunk, 1, sizeof chunk, file.get())) > 0) {
    if (got > max_bytes - out.size()) {
      error = "is larger than " + in_units(max_bytes);
      return false;
    }
    out.insert(out.end(), chunk, chunk + got);
  }
  if (std::ferror(file.get())) {
    error = std::string("cannot be read: ") + std::strerror(errno);
    return false;
  }
  return true;
}

} // namespace

std::optional<std::string> read_input_file(const std::filesystem::path &path, std::size_t max_bytes,
                                           std::string &error) {
  std::string text;
  if (!read_bounded(path, max_bytes, text, error))
    return std::nullopt;
  return text;
}

bool read_input_file(const std::filesystem::path &path, std::size_t max_bytes,
                     std::vector<unsigned char> &bytes, std::string &error) {
  return read_bounded(path, max_bytes, bytes, error);
}

} // namespace camhead::base
