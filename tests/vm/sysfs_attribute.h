// sysfs and configfs attributes, as the lab's checks set up their devices
// (gpio-sim's banks, a PCI device's remove and rescan, a USB gadget's
// plug). Errors throw
// std::runtime_error naming the file and errno.
#pragma once

#include <string>

namespace camhead::vm {

// Writes `text` to the attribute in one write(), as sysfs and configfs
// take a value.
void write_attribute(const std::string &path, const std::string &text);
// The attribute's first line, without the newline.
[[nodiscard]] std::string read_attribute(const std::string &path);
// Whether the kernel has a USB device of this serial number enumerated (in
// /sys/bus/usb/devices): a replugged board is back on the bus.
[[nodiscard]] bool usb_device_enumerated(const std::string &serial);

} // namespace camhead::vm
