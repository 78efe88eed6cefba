// A kernel gpio-sim chip for the hardware lab's guest, made and removed
// through configfs the way libgpiod's own tests do (make_sim()). Writing a
// line's `pull` attribute in sysfs moves an input line as a real signal
// would, and the kernel delivers real edge events for it.
//
// Layout (Linux 6.1): /sys/kernel/config/gpio-sim/<name>/{live,dev_name},
// .../bank0/{num_lines,label,chip_name}; the lines' attributes live in
// /sys/devices/platform/<dev_name>/<chip_name>/sim_gpio<N>/{pull,value}.
//
// Errors throw std::runtime_error naming the file: this is test set-up.
#pragma once

#include <string>

namespace camhead::vm {

class GpioSim {
public:
  // Creates the chip with one bank of `num_lines` lines labelled `label` and
  // brings it live. Every line starts pulled down (low).
  GpioSim(const std::string &name, unsigned num_lines, const std::string &label);
  ~GpioSim();
  GpioSim(const GpioSim &) = delete;
  GpioSim &operator=(const GpioSim &) = delete;

  // "gpiochip1": the character device /dev/<chip_name()>.
  [[nodiscard]] const std::string &chip_name() const { return chip_name_; }
  [[nodiscard]] const std::string &label() const { return label_; }

  // Takes the chip away (false: the kernel removes the gpiochip, as when a
  // board is unplugged) or brings it back (possibly under another name) with
  // every line pulled down again.
  void set_live(bool live);

  // Pulls an input line up (high) or down (low). A requested line with edge
  // detection sees an edge when the level changes.
  void set_pull(unsigned offset, bool up) const;
  // The line's level as the simulator holds it.
  [[nodiscard]] bool value(unsigned offset) const;

private:
  void find_chip();

  std::string config_dir_, bank_dir_, sysfs_dir_, chip_name_, label_;
};

} // namespace camhead::vm
