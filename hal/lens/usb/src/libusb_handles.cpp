// libusb helpers of the lens backend; see libusb_handles.h.
#include "libusb_handles.h"

#include <array>
#include <ctime>
#include <span>

#include "camhead/hal/lens/usb/usb_lens_protocol.h"

namespace camhead::hal::lens::detail {
namespace {

// GET_INFO is answered from the board's firmware at once; a board that does
// not know it stalls, so a short timeout only matters for a hung board.
constexpr unsigned kControlTimeoutMs = 200;

} // namespace

DeviceList::~DeviceList() {
  if (list_ != nullptr) {
    libusb().free_device_list(list_, 1);
  }
}

std::string error_name(int code) {
  return libusb().error_name(code);
}

const char *transfer_status_name(libusb_transfer_status status) {
  switch (status) {
  case LIBUSB_TRANSFER_COMPLETED:
    return "LIBUSB_TRANSFER_COMPLETED";
  case LIBUSB_TRANSFER_ERROR:
    return "LIBUSB_TRANSFER_ERROR";
  case LIBUSB_TRANSFER_TIMED_OUT:
    return "LIBUSB_TRANSFER_TIMED_OUT";
  case LIBUSB_TRANSFER_CANCELLED:
    return "LIBUSB_TRANSFER_CANCELLED";
  case LIBUSB_TRANSFER_STALL:
    return "LIBUSB_TRANSFER_STALL";
  case LIBUSB_TRANSFER_NO_DEVICE:
    return "LIBUSB_TRANSFER_NO_DEVICE";
  case LIBUSB_TRANSFER_OVERFLOW:
    return "LIBUSB_TRANSFER_OVERFLOW";
  }
  return "unknown transfer status";
}

std::string where(libusb_device *dev) {
  return "bus " + std::to_string(libusb().get_bus_number(dev)) + " device " +
         std::to_string(libusb().get_device_address(dev));
}

std::optional<LensInterface> find_lens_interface(const libusb_config_descriptor &config) {
  for (int i = 0; i < config.bNumInterfaces; ++i) {
    const libusb_interface &iface = config.interface[i];
    if (iface.num_altsetting < 1) {
      continue;
    }
    const libusb_interface_descriptor &alt = iface.altsetting[0];
    if (alt.bInterfaceClass != kUsbLensInterfaceClass ||
        alt.bInterfaceSubClass != kUsbLensInterfaceSubClass ||
        alt.bInterfaceProtocol != kUsbLensInterfaceProtocol) {
      continue;
    }
    for (int e = 0; e < alt.bNumEndpoints; ++e) {
      const libusb_endpoint_descriptor &ep = alt.endpoint[e];
      const int type = ep.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK;
      if ((ep.bEndpointAddress & LIBUSB_ENDPOINT_DIR_MASK) == LIBUSB_ENDPOINT_IN &&
          (type == LIBUSB_TRANSFER_TYPE_INTERRUPT || type == LIBUSB_TRANSFER_TYPE_BULK)) {
        return LensInterface{alt.bInterfaceNumber, ep.bEndpointAddress,
                             static_cast<std::uint16_t>(ep.wMaxPacketSize & 0x7FF),
                             type == LIBUSB_TRANSFER_TYPE_INTERRUPT};
      }
    }
  }
  return std::nullopt;
}

std::string read_serial(libusb_device_handle *handle, const libusb_device_descriptor &desc) {
  if (desc.iSerialNumber == 0) {
    return {};
  }
  std::array<unsigned char, 64> text{};
  const int n = libusb().get_string_descriptor_ascii(handle, desc.iSerialNumber, text.data(),
                                                     static_cast<int>(text.size()));
  return n > 0
             ? std::string(reinterpret_cast<const char *>(text.data()), static_cast<std::size_t>(n))
             : std::string{};
}

std::string read_board_info(libusb_device_handle *handle, int interface) {
  std::array<unsigned char, kUsbLensInfoSize> buffer{};
  const int rc =
      libusb().control_transfer(handle, kUsbLensGetInfoRequestType, kUsbLensGetInfoRequest, 0,
                                static_cast<std::uint16_t>(interface), buffer.data(),
                                static_cast<std::uint16_t>(buffer.size()), kControlTimeoutMs);
  if (rc < 0) {
    return "no GET_INFO: " + error_name(rc);
  }
  const BoardInfoParseResult info =
      parse_board_info(std::span<const std::uint8_t>(buffer.data(), static_cast<std::size_t>(rc)));
  if (!info) {
    return "no GET_INFO: " + info.detail;
  }
  return "firmware " + firmware_version_string(info.info->firmware_version) + ", " +
         std::to_string(info.info->report_rate_hz) + " Hz";
}

} // namespace camhead::hal::lens::detail
