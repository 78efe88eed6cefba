#include "web_access.h"

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include <arpa/inet.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace camhead::pipeline::web {
namespace {

std::string octal_mode(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", unsigned(mode & 07777));
  return text;
}

} // namespace

ListenAddress parse_listen(const std::string &text, const std::string &what) {
  const auto wrong = [&](const std::string &why) {
    return WebAccessError((what.empty() ? "" : what + ": ") + "'" + text + "' " + why +
                          " (PORT, ADDRESS:PORT or [IPv6]:PORT, such as 8080, "
                          "127.0.0.1:8080 or 0.0.0.0:8080)");
  };
  for (const char c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      throw WebAccessError((what.empty() ? "" : what + ": ") +
                           "has a control character (PORT, ADDRESS:PORT or [IPv6]:PORT)");
  ListenAddress out{"127.0.0.1", 0};
  std::string port = text;
  if (!text.empty() && text.front() == '[') {
    const std::size_t close = text.find("]:");
    if (close == std::string::npos)
      throw wrong("has no ]:PORT after its IPv6 address");
    out.host = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else if (const std::size_t colon = text.rfind(':'); colon != std::string::npos) {
    out.host = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || ec != std::errc() || end != port.data() + port.size() || value > 65535)
    throw wrong("has no port from 0 to 65535");
  out.port = std::uint16_t(value);
  if (out.host == "localhost")
    return out;
  unsigned char address[16];
  if (inet_pton(AF_INET, out.host.c_str(), address) != 1 &&
      inet_pton(AF_INET6, out.host.c_str(), address) != 1)
    throw wrong("is not a numeric address or localhost");
  return out;
}

bool is_loopback(const std::string &host) {
  in_addr v4{};
  if (inet_pton(AF_INET, host.c_str(), &v4) == 1)
    return (ntohl(v4.s_addr) >> 24) == 127;
  return host == "::1" || host == "localhost";
}

std::string read_password_file(const std::filesystem::path &file) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0)
    throw WebAccessError(file.string() + ": " + std::strerror(errno) + " (`camhead web-password " +
                         file.string() + "` sets a password)");
  if (!S_ISREG(st.st_mode))
    throw WebAccessError(file.string() + ": not a file");
  if ((st.st_mode & 077) != 0)
    throw WebAccessError(file.string() + ": others may read or change it (mode " +
                         octal_mode(st.st_mode) + "): `chmod 600 " + file.string() + "`");
  std::ifstream in(file);
  std::string line;
  if (!in || !std::getline(in, line))
    line.clear();
  if (line.size() < 4 || line.front() != '$' || line.find_first_of(" :\t") != std::string::npos)
    throw WebAccessError(file.string() + ": holds no password hash (`camhead web-password " +
                         file.string() + "` sets one)");
  return line;
}

void write_password_file(const std::filesystem::path &file, const std::string &hash) {
  const std::filesystem::path partial = file.string() + ".partial";
  const auto fail = [&](const std::string &why) {
    ::unlink(partial.c_str());
    return WebAccessError(file.string() + ": " + why);
  };
  ::unlink(partial.c_str());
  const int fd = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0)
    throw WebAccessError(partial.string() + ": " + std::strerror(errno));
  // A file that exists keeps its owner: the package's belongs to the
  // service's user, who must read it, and root sets the password.
  struct stat existing {};
  const bool keep_owner = ::stat(file.c_str(), &existing) == 0 && ::geteuid() == 0;
  const std::string line = hash + "\n";
  const bool written =
      ::write(fd, line.data(), line.size()) == ssize_t(line.size()) && ::fchmod(fd, 0600) == 0 &&
      (!keep_owner || ::fchown(fd, existing.st_uid, existing.st_gid) == 0) && ::fsync(fd) == 0;
  const int error = errno;
  if (::close(fd) != 0 || !written)
    throw fail(std::strerror(error));
  if (::rename(partial.c_str(), file.c_str()) != 0)
    throw fail(std::strerror(errno));
}

} // namespace camhead::pipeline::web
