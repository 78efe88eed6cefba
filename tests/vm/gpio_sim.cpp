#include "gpio_sim.h"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

#include "sysfs_attribute.h"

namespace camhead::vm {
namespace {

constexpr const char *kConfigRoot = "/sys/kernel/config/gpio-sim";

[[noreturn]] void fail(const std::string &what, const std::string &path) {
  throw std::runtime_error("gpio-sim: " + what + " " + path + ": " + std::strerror(errno));
}

void make_directory(const std::string &path) {
  if (::mkdir(path.c_str(), 0755) != 0) {
    fail("cannot create", path);
  }
}

} // namespace

GpioSim::GpioSim(const std::string &name, unsigned num_lines, const std::string &label)
    : config_dir_(std::string(kConfigRoot) + "/" + name), bank_dir_(config_dir_ + "/bank0"),
      label_(label) {
  make_directory(config_dir_);
  make_directory(bank_dir_);
  write_attribute(bank_dir_ + "/num_lines", std::to_string(num_lines));
  write_attribute(bank_dir_ + "/label", label);
  set_live(true);
}

void GpioSim::set_live(bool live) {
  write_attribute(config_dir_ + "/live", live ? "1" : "0");
  if (live) {
    find_chip();
  }
}

void GpioSim::find_chip() {
  const std::string dev_name = read_attribute(config_dir_ + "/dev_name");
  chip_name_ = read_attribute(bank_dir_ + "/chip_name");
  sysfs_dir_ = "/sys/devices/platform/" + dev_name + "/" + chip_name_;
}

GpioSim::~GpioSim() {
  // Best effort: the guest powers off after the checks anyway.
  try {
    write_attribute(config_dir_ + "/live", "0");
  } catch (const std::exception &) {
  }
  ::rmdir(bank_dir_.c_str());
  ::rmdir(config_dir_.c_str());
}

void GpioSim::set_pull(unsigned offset, bool up) const {
  write_attribute(sysfs_dir_ + "/sim_gpio" + std::to_string(offset) + "/pull",
                  up ? "pull-up" : "pull-down");
}

bool GpioSim::value(unsigned offset) const {
  return read_attribute(sysfs_dir_ + "/sim_gpio" + std::to_string(offset) + "/value") == "1";
}

} // namespace camhead::vm
