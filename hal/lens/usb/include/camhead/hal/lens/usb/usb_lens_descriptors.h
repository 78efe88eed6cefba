// The lens board's USB descriptors (docs/usb-lens-protocol.md, section 2) as
// bytes, and the two blobs a Linux FunctionFS gadget writes to ep0 to become
// one (section 7).
//
// Why here and not in the gadget program: the descriptors are part of the
// protocol. The host backend matches the same class/subclass/protocol, the
// VM gadget serves exactly these bytes, and a unit test checks the FunctionFS
// blobs field by field against the kernel's <linux/usb/functionfs.h> structs.
// Built by hand, byte by byte, so this header needs no Linux header and the
// library still compiles anywhere the codec does.
//
// Pure; any thread.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "camhead/hal/lens/usb/usb_lens_protocol.h"

namespace camhead::hal::lens {

// Endpoint 1 IN, interrupt, 64-byte packets, polled every 1 ms: bInterval 1
// at full speed (frames), 4 at high speed (2^(4-1) microframes of 125 us).
inline constexpr std::uint8_t kUsbLensEndpointAddress = 0x81;
inline constexpr std::uint8_t kUsbLensEndpointAttributes = 0x03; // interrupt
inline constexpr std::uint16_t kUsbLensMaxPacketSize = 64;
inline constexpr std::uint8_t kUsbLensFullSpeedInterval = 1;
inline constexpr std::uint8_t kUsbLensHighSpeedInterval = 4;

// String descriptors. The device-level ones come from the board's firmware
// (or, in the VM, from configfs); the interface string from the interface.
inline constexpr const char *kUsbLensManufacturer = "camhead";
inline constexpr const char *kUsbLensProduct = "camhead lens encoder";
inline constexpr const char *kUsbLensInterfaceName = "camhead lens encoder v1";
inline constexpr std::uint16_t kUsbLangEnglishUs = 0x0409;

inline constexpr std::size_t kUsbInterfaceDescriptorSize = 9;
inline constexpr std::size_t kUsbEndpointDescriptorSize = 7;

enum class UsbSpeed { full, high };

// Interface 0 (class/subclass/protocol of usb_lens_protocol.h, iInterface 1)
// followed by its one endpoint descriptor: 16 bytes.
[[nodiscard]] std::array<std::uint8_t, kUsbInterfaceDescriptorSize + kUsbEndpointDescriptorSize>
usb_lens_interface_descriptors(UsbSpeed speed);

// FunctionFS descriptors blob: header with FUNCTIONFS_DESCRIPTORS_MAGIC_V2
// (3), total length and flags FUNCTIONFS_HAS_FS_DESC | FUNCTIONFS_HAS_HS_DESC,
// the two descriptor counts, then the full-speed and the high-speed
// descriptors. All little-endian.
[[nodiscard]] std::vector<std::uint8_t> functionfs_descriptors();

// FunctionFS strings blob: FUNCTIONFS_STRINGS_MAGIC (2), total length, one
// string, one language (0x0409), the interface name NUL-terminated.
[[nodiscard]] std::vector<std::uint8_t> functionfs_strings();

} // namespace camhead::hal::lens
