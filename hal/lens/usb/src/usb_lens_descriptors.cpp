// The lens board's descriptors and FunctionFS blobs; see usb_lens_descriptors.h.
#include "camhead/hal/lens/usb/usb_lens_descriptors.h"

#include <cstring>

namespace camhead::hal::lens {
namespace {

// USB 2.0 chapter 9 descriptor types.
constexpr std::uint8_t kDescriptorInterface = 0x04;
constexpr std::uint8_t kDescriptorEndpoint = 0x05;

// <linux/usb/functionfs.h>, spelled out so that this file compiles without it;
// tests/hal/lens/usb checks them against the kernel header.
constexpr std::uint32_t kFfsDescriptorsMagicV2 = 3;
constexpr std::uint32_t kFfsStringsMagic = 2;
constexpr std::uint32_t kFfsHasFsDesc = 1;
constexpr std::uint32_t kFfsHasHsDesc = 2;

void append_u16(std::vector<std::uint8_t> &out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}

void append_u32(std::vector<std::uint8_t> &out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) {
    out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
}

void patch_u32(std::vector<std::uint8_t> &out, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) {
    out[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
  }
}

} // namespace

std::array<std::uint8_t, kUsbInterfaceDescriptorSize + kUsbEndpointDescriptorSize>
usb_lens_interface_descriptors(UsbSpeed speed) {
  const std::uint8_t interval =
      speed == UsbSpeed::high ? kUsbLensHighSpeedInterval : kUsbLensFullSpeedInterval;
  return {
      // Interface descriptor
      static_cast<std::uint8_t>(kUsbInterfaceDescriptorSize), // bLength
      kDescriptorInterface,                                   // bDescriptorType
      0,                                                      // bInterfaceNumber
      0,                                                      // bAlternateSetting
      1,                                                      // bNumEndpoints
      kUsbLensInterfaceClass,                                 // bInterfaceClass
      kUsbLensInterfaceSubClass,                              // bInterfaceSubClass
      kUsbLensInterfaceProtocol,                              // bInterfaceProtocol
      1,                                                      // iInterface
      // Endpoint descriptor
      static_cast<std::uint8_t>(kUsbEndpointDescriptorSize), // bLength
      kDescriptorEndpoint,                                   // bDescriptorType
      kUsbLensEndpointAddress,                               // bEndpointAddress
      kUsbLensEndpointAttributes,                            // bmAttributes
      static_cast<std::uint8_t>(kUsbLensMaxPacketSize),      // wMaxPacketSize, low byte
      static_cast<std::uint8_t>(kUsbLensMaxPacketSize >> 8), // wMaxPacketSize, high byte
      interval,                                              // bInterval
  };
}

std::vector<std::uint8_t> functionfs_descriptors() {
  std::vector<std::uint8_t> out;
  append_u32(out, kFfsDescriptorsMagicV2);
  append_u32(out, 0); // length, patched below
  append_u32(out, kFfsHasFsDesc | kFfsHasHsDesc);
  append_u32(out, 2); // fs_count: interface + endpoint
  append_u32(out, 2); // hs_count
  for (const UsbSpeed speed : {UsbSpeed::full, UsbSpeed::high}) {
    const auto descriptors = usb_lens_interface_descriptors(speed);
    out.insert(out.end(), descriptors.begin(), descriptors.end());
  }
  patch_u32(out, 4, static_cast<std::uint32_t>(out.size()));
  return out;
}

std::vector<std::uint8_t> functionfs_strings() {
  std::vector<std::uint8_t> out;
  append_u32(out, kFfsStringsMagic);
  append_u32(out, 0); // length, patched below
  append_u32(out, 1); // str_count
  append_u32(out, 1); // lang_count
  append_u16(out, kUsbLangEnglishUs);
  const std::size_t n = std::strlen(kUsbLensInterfaceName);
  out.insert(out.end(), kUsbLensInterfaceName, kUsbLensInterfaceName + n);
  out.push_back(0);
  patch_u32(out, 4, static_cast<std::uint32_t>(out.size()));
  return out;
}

} // namespace camhead::hal::lens
