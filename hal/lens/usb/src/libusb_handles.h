// libusb for the lens backend: RAII for its C handles and the questions the
// transport asks a device before it streams from it (which interface, which
// endpoint, which serial, what GET_INFO says). Private to
// camhead_hal_lens_usb: with libusb_library.h, the only header that includes
// <libusb.h>; only the libusb_*.cpp files include them.
//
// Thread safety: the functions are as thread-safe as libusb's; the transport
// calls them all from its event thread.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "camhead/hal/lens/monotonic_clock.h"
#include "libusb_library.h"

namespace camhead::hal::lens::detail {

struct ContextDeleter {
  void operator()(libusb_context *c) const { libusb().exit(c); }
};
struct HandleDeleter {
  void operator()(libusb_device_handle *h) const { libusb().close(h); }
};
struct DeviceDeleter {
  void operator()(libusb_device *d) const { libusb().unref_device(d); }
};
struct TransferDeleter {
  void operator()(libusb_transfer *t) const { libusb().free_transfer(t); }
};
struct ConfigDeleter {
  void operator()(libusb_config_descriptor *c) const { libusb().free_config_descriptor(c); }
};
using ContextPtr = std::unique_ptr<libusb_context, ContextDeleter>;
using HandlePtr = std::unique_ptr<libusb_device_handle, HandleDeleter>;
using DevicePtr = std::unique_ptr<libusb_device, DeviceDeleter>; // holds one reference
// A transfer that has been submitted holds a reference to its device until it
// is freed (or submitted again): free it before the handle is closed and the
// context exited, like a DevicePtr.
using TransferPtr = std::unique_ptr<libusb_transfer, TransferDeleter>;
using ConfigPtr = std::unique_ptr<libusb_config_descriptor, ConfigDeleter>;

// libusb_get_device_list's array, unreferencing its devices on destruction.
class DeviceList {
public:
  explicit DeviceList(libusb_context *ctx) : count_(libusb().get_device_list(ctx, &list_)) {}
  ~DeviceList();
  DeviceList(const DeviceList &) = delete;
  DeviceList &operator=(const DeviceList &) = delete;
  // Negative: a libusb error code.
  [[nodiscard]] ssize_t count() const { return count_; }
  [[nodiscard]] libusb_device *operator[](ssize_t i) const { return list_[i]; }

private:
  libusb_device **list_ = nullptr;
  ssize_t count_;
};

using lens::monotonic_ns;

// "LIBUSB_ERROR_NO_DEVICE", "LIBUSB_TRANSFER_STALL": the names in messages.
[[nodiscard]] std::string error_name(int code);
[[nodiscard]] const char *transfer_status_name(libusb_transfer_status status);

// "bus 1 device 4": how messages name a device.
[[nodiscard]] std::string where(libusb_device *dev);

// The lens interface of a configuration: the protocol's class, subclass and
// protocol at alternate setting 0, and its IN endpoint (interrupt, or bulk
// from a board that prefers it). The endpoint address comes from here, not
// from the protocol's table: a Linux gadget may renumber it.
struct LensInterface {
  int number = -1;
  std::uint8_t endpoint = 0;
  std::uint16_t max_packet = 0;
  bool interrupt = true;
};
[[nodiscard]] std::optional<LensInterface>
find_lens_interface(const libusb_config_descriptor &config);

// The iSerialNumber string, empty where there is none or it cannot be read.
[[nodiscard]] std::string read_serial(libusb_device_handle *handle,
                                      const libusb_device_descriptor &desc);

// GET_INFO, for the status text: "firmware 1.2.3, 500 Hz", or "no GET_INFO:
// why" (the request is optional; a board without it works all the same).
[[nodiscard]] std::string read_board_info(libusb_device_handle *handle, int interface);

} // namespace camhead::hal::lens::detail
