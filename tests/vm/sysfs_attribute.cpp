// See sysfs_attribute.h.
#include "sysfs_attribute.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace camhead::vm {
namespace {

[[noreturn]] void fail(const std::string &what, const std::string &path) {
  throw std::runtime_error(what + " " + path + ": " + std::strerror(errno));
}

} // namespace

void write_attribute(const std::string &path, const std::string &text) {
  // One write() call: configfs and sysfs attributes take the value in one go.
  std::ofstream file(path);
  if (!file) {
    fail("cannot open", path);
  }
  file << text << std::flush;
  if (!file) {
    fail("cannot write '" + text + "' to", path);
  }
}

std::string read_attribute(const std::string &path) {
  std::ifstream file(path);
  std::string line;
  if (!file || !std::getline(file, line)) {
    fail("cannot read", path);
  }
  return line;
}

bool usb_device_enumerated(const std::string &serial) {
  std::error_code ec;
  for (const auto &entry : std::filesystem::directory_iterator("/sys/bus/usb/devices", ec)) {
    std::ifstream in(entry.path() / "serial");
    std::string line;
    if (std::getline(in, line) && line == serial)
      return true;
  }
  return false;
}

} // namespace camhead::vm
