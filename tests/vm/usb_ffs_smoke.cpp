// Hardware-lab infrastructure check: a FunctionFS gadget served by this
// program on dummy_hcd enumerates, libusb finds it by VID:PID and bulk data
// goes out and comes back. Independent of camhead's USB lens code, so that a
// failure here points at the lab (modules, configfs, FunctionFS, libusb), not
// at the lens protocol.
//
//   camhead_vm_usb_smoke gadget FFS_DIR   serve the gadget: descriptors, then
//                                         echo bulk OUT to bulk IN (until killed)
//   camhead_vm_usb_smoke host VID PID     prints RESULT usb_ffs_enumerate and
//                                         RESULT usb_ffs_bulk_echo
//
// usb_ffs_smoke.sh makes the configfs gadget around them.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <libusb.h>
#include <linux/usb/ch9.h>
#include <linux/usb/functionfs.h>
#include <unistd.h>

#include "vm_result.h"

namespace {

// --- Gadget side -------------------------------------------------------------

void append_le32(std::vector<std::uint8_t> &out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) {
    out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  }
}

template <typename T> void append_struct(std::vector<std::uint8_t> &out, const T &value) {
  const auto *bytes = reinterpret_cast<const std::uint8_t *>(&value);
  out.insert(out.end(), bytes, bytes + sizeof value);
}

// One vendor-class interface with a bulk OUT and a bulk IN endpoint, for full
// and high speed. FunctionFS numbers the endpoint files in descriptor order:
// ep1 is OUT, ep2 is IN.
std::vector<std::uint8_t> descriptors() {
  std::vector<std::uint8_t> body;
  append_le32(body, 3); // full-speed descriptor count
  append_le32(body, 3); // high-speed descriptor count
  for (const std::uint16_t packet : {64, 512}) {
    usb_interface_descriptor interface {};
    interface.bLength = USB_DT_INTERFACE_SIZE;
    interface.bDescriptorType = USB_DT_INTERFACE;
    interface.bNumEndpoints = 2;
    interface.bInterfaceClass = USB_CLASS_VENDOR_SPEC;
    interface.iInterface = 1;
    append_struct(body, interface);
    for (const std::uint8_t address : {1 | USB_DIR_OUT, 2 | USB_DIR_IN}) {
      usb_endpoint_descriptor_no_audio endpoint{};
      endpoint.bLength = USB_DT_ENDPOINT_SIZE;
      endpoint.bDescriptorType = USB_DT_ENDPOINT;
      endpoint.bEndpointAddress = address;
      endpoint.bmAttributes = USB_ENDPOINT_XFER_BULK;
      endpoint.wMaxPacketSize = packet; // little-endian host
      append_struct(body, endpoint);
    }
  }
  std::vector<std::uint8_t> out;
  append_le32(out, FUNCTIONFS_DESCRIPTORS_MAGIC_V2);
  append_le32(out, static_cast<std::uint32_t>(12 + body.size()));
  append_le32(out, FUNCTIONFS_HAS_FS_DESC | FUNCTIONFS_HAS_HS_DESC);
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

std::vector<std::uint8_t> strings() {
  const char text[] = "camhead lab smoke";
  std::vector<std::uint8_t> out;
  append_le32(out, FUNCTIONFS_STRINGS_MAGIC);
  append_le32(out, static_cast<std::uint32_t>(16 + 2 + sizeof text));
  append_le32(out, 1); // strings per language
  append_le32(out, 1); // languages
  out.push_back(0x09); // en-US, 0x0409 little-endian
  out.push_back(0x04);
  out.insert(out.end(), text, text + sizeof text);
  return out;
}

void write_all(int fd, std::span<const std::uint8_t> bytes, const std::string &what) {
  if (::write(fd, bytes.data(), bytes.size()) != static_cast<ssize_t>(bytes.size())) {
    throw std::runtime_error(what + ": " + std::strerror(errno));
  }
}

int open_or_throw(const std::string &path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) {
    throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  }
  return fd;
}

[[noreturn]] void serve_gadget(const std::string &dir) {
  const int ep0 = open_or_throw(dir + "/ep0", O_RDWR);
  write_all(ep0, descriptors(), "writing descriptors to " + dir + "/ep0");
  write_all(ep0, strings(), "writing strings to " + dir + "/ep0");
  // The endpoint files exist now; usb_ffs_smoke.sh binds the UDC when it sees
  // them. Reads block until the host configures the device.
  const int out = open_or_throw(dir + "/ep1", O_RDWR);
  const int in = open_or_throw(dir + "/ep2", O_RDWR);
  std::vector<std::uint8_t> buffer(512);
  for (;;) {
    const ssize_t n = ::read(out, buffer.data(), buffer.size());
    if (n < 0) {
      // ESHUTDOWN while the host is not (yet) configured: wait and retry.
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      continue;
    }
    if (::write(in, buffer.data(), static_cast<std::size_t>(n)) != n) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

// --- Host side ---------------------------------------------------------------

struct Endpoints {
  std::uint8_t in = 0, out = 0;
};

Endpoints find_bulk_endpoints(libusb_device *device) {
  libusb_config_descriptor *config = nullptr;
  if (libusb_get_active_config_descriptor(device, &config) != 0) {
    throw std::runtime_error("no active configuration");
  }
  Endpoints found;
  if (config->bNumInterfaces > 0 && config->interface[0].num_altsetting > 0) {
    const libusb_interface_descriptor &interface = config->interface[0].altsetting[0];
    for (int i = 0; i < interface.bNumEndpoints; ++i) {
      const libusb_endpoint_descriptor &endpoint = interface.endpoint[i];
      if ((endpoint.bmAttributes & 3) == LIBUSB_TRANSFER_TYPE_BULK) {
        ((endpoint.bEndpointAddress & LIBUSB_ENDPOINT_IN) ? found.in : found.out) =
            endpoint.bEndpointAddress;
      }
    }
  }
  libusb_free_config_descriptor(config);
  if (found.in == 0 || found.out == 0) {
    throw std::runtime_error("interface 0 lacks a bulk IN or OUT endpoint");
  }
  return found;
}

std::string bulk_echo(libusb_device_handle *handle, Endpoints endpoints) {
  if (const int rc = libusb_claim_interface(handle, 0); rc != 0) {
    throw std::runtime_error(std::string("claiming interface 0: ") + libusb_error_name(rc));
  }
  constexpr int kRounds = 20;
  for (int round = 0; round < kRounds; ++round) {
    std::vector<std::uint8_t> sent(100 + round);
    for (std::size_t i = 0; i < sent.size(); ++i) {
      sent[i] = static_cast<std::uint8_t>(i * 7 + static_cast<std::size_t>(round));
    }
    int done = 0;
    if (const int rc = libusb_bulk_transfer(handle, endpoints.out, sent.data(),
                                            static_cast<int>(sent.size()), &done, 2000);
        rc != 0 || done != static_cast<int>(sent.size())) {
      throw std::runtime_error("round " + std::to_string(round) +
                               ": bulk OUT: " + libusb_error_name(rc));
    }
    std::vector<std::uint8_t> got(512);
    if (const int rc = libusb_bulk_transfer(handle, endpoints.in, got.data(),
                                            static_cast<int>(got.size()), &done, 2000);
        rc != 0) {
      throw std::runtime_error("round " + std::to_string(round) +
                               ": bulk IN: " + libusb_error_name(rc));
    }
    got.resize(static_cast<std::size_t>(done));
    if (got != sent) {
      throw std::runtime_error("round " + std::to_string(round) + ": echoed " +
                               std::to_string(done) + " bytes differ from the " +
                               std::to_string(sent.size()) + " sent");
    }
  }
  libusb_release_interface(handle, 0);
  return std::to_string(kRounds) + " bulk OUT/IN round trips of 100-119 bytes echoed";
}

int probe_host(std::uint16_t vid, std::uint16_t pid) {
  char id[16];
  std::snprintf(id, sizeof id, "%04x:%04x", vid, pid);
  // Each try starts a fresh libusb context, which scans sysfs anew: without
  // udev, a context only learns of devices added later from netlink events,
  // and one that saw the device half-enumerated would never look again.
  libusb_context *context = nullptr;
  libusb_device_handle *handle = nullptr;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (;;) {
    if (libusb_init(&context) != 0) {
      context = nullptr;
    } else if ((handle = libusb_open_device_with_vid_pid(context, vid, pid)) != nullptr) {
      break;
    }
    if (context != nullptr) {
      libusb_exit(context);
      context = nullptr;
    }
    if (std::chrono::steady_clock::now() >= deadline) {
      camhead::vm::print_result("usb_ffs_enumerate", false,
                                std::string("libusb found no ") + id + " within 10 s");
      camhead::vm::print_result("usb_ffs_bulk_echo", false, "not reached");
      return 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  libusb_device *device = libusb_get_device(handle);
  static const char *const kSpeeds[] = {"unknown", "low", "full", "high", "super", "super+"};
  const int speed = libusb_get_device_speed(device);
  camhead::vm::print_result("usb_ffs_enumerate", true,
                            std::string(id) + " on bus " +
                                std::to_string(libusb_get_bus_number(device)) + " device " +
                                std::to_string(libusb_get_device_address(device)) + ", " +
                                kSpeeds[speed >= 0 && speed <= 5 ? speed : 0] + " speed");
  try {
    camhead::vm::print_result("usb_ffs_bulk_echo", true,
                              bulk_echo(handle, find_bulk_endpoints(device)));
  } catch (const std::exception &error) {
    camhead::vm::print_result("usb_ffs_bulk_echo", false, error.what());
  }
  libusb_close(handle);
  libusb_exit(context);
  return 0;
}

} // namespace

int main(int argc, char **argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  try {
    if (mode == "gadget" && argc == 3) {
      serve_gadget(argv[2]);
    }
    if (mode == "host" && argc == 4) {
      return probe_host(static_cast<std::uint16_t>(std::stoul(argv[2], nullptr, 16)),
                        static_cast<std::uint16_t>(std::stoul(argv[3], nullptr, 16)));
    }
  } catch (const std::exception &error) {
    std::fprintf(stderr, "camhead_vm_usb_smoke %s: %s\n", mode.c_str(), error.what());
    return 1;
  }
  std::fprintf(stderr, "usage: camhead_vm_usb_smoke gadget FFS_DIR | host VID PID\n");
  return 2;
}
