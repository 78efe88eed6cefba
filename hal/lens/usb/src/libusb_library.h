// libusb-1.0, opened at run time (camhead/hal/shared_library.h): the
// functions the lens backend calls, as a table typed from <libusb.h>. Call
// libusb().init(&ctx) where a linked program would call libusb_init(&ctx).
// libusb_fill_*_transfer are inline in the header and stay direct calls.
//
// Thread safety: the first call of either function loads the library
// (a function-local static); after that, both from any thread.
#pragma once

#include <string>

#include <libusb.h>

namespace camhead::hal::lens::detail {

// Each X(name) is libusb_<name>.
#define CAMHEAD_LIBUSB_FUNCTIONS(X)                                                                \
  X(alloc_transfer)                                                                                \
  X(cancel_transfer)                                                                               \
  X(claim_interface)                                                                               \
  X(clear_halt)                                                                                    \
  X(close)                                                                                         \
  X(control_transfer)                                                                              \
  X(error_name)                                                                                    \
  X(exit)                                                                                          \
  X(free_config_descriptor)                                                                        \
  X(free_device_list)                                                                              \
  X(free_transfer)                                                                                 \
  X(get_active_config_descriptor)                                                                  \
  X(get_bus_number)                                                                                \
  X(get_device)                                                                                    \
  X(get_device_address)                                                                            \
  X(get_device_descriptor)                                                                         \
  X(get_device_list)                                                                               \
  X(get_string_descriptor_ascii)                                                                   \
  X(handle_events_timeout_completed)                                                               \
  X(has_capability)                                                                                \
  X(hotplug_deregister_callback)                                                                   \
  X(hotplug_register_callback)                                                                     \
  X(init)                                                                                          \
  X(open)                                                                                          \
  X(ref_device)                                                                                    \
  X(release_interface)                                                                             \
  X(set_auto_detach_kernel_driver)                                                                 \
  X(submit_transfer)                                                                               \
  X(unref_device)

struct LibusbFunctions {
#define CAMHEAD_LIBUSB_POINTER(name) decltype(&::libusb_##name) name = nullptr;
  CAMHEAD_LIBUSB_FUNCTIONS(CAMHEAD_LIBUSB_POINTER)
#undef CAMHEAD_LIBUSB_POINTER
};

// "" once libusb-1.0.so.0 is open with every function above; otherwise why
// not, naming the file and its Debian package.
[[nodiscard]] const std::string &libusb_load_error();

// The table. Only after libusb_load_error() returned "": otherwise it aborts
// with that error (a caller that did not ask is a bug, not a user's problem).
[[nodiscard]] const LibusbFunctions &libusb();

} // namespace camhead::hal::lens::detail
