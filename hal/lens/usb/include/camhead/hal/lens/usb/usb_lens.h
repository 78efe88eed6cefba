// The USB lens-encoder board as a LensEncoder (docs/usb-lens-protocol.md).
//
// open_usb_lens() never fails for want of a board: with none plugged in it
// returns a source that reports connected = false ("usb 1209:0001: not
// connected, waiting") and picks the board up when it appears; when the board
// goes away mid-stream it closes it, waits, and counts a reconnect when it
// comes back. The pipeline keeps running through all of it.
//
// Inside, a thread of the backend's own runs libusb's event loop: hotplug
// (libusb_hotplug_register_callback where libusb has it) plus a fresh
// enumeration every rescan_interval while disconnected, because libusb's
// hotplug hears nothing on a system without udevd (the VM test's busybox
// guest, minimal containers). Four interrupt transfers stay queued on the
// board's endpoint, each report is stamped on completion, parsed, mapped to
// CLOCK_MONOTONIC (device_clock.h) and queued for poll(). libusb's types stay
// in the .cpp.
//
// Status: malformed counts reports rejected by parse_report (and transfers
// longer than a packet); lost counts sequence gaps and readings dropped from
// a full queue; reconnects counts returns after the board went away.
//
// Thread safety: poll() from one thread at a time (the lens thread); name()
// and status() from any thread; destroy from the thread that polls, never
// while poll() runs. The destructor stops the backend's thread (at most about
// 50 ms) and releases the board.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "camhead/hal/lens/lens_encoder.h"
#include "camhead/hal/lens/usb/usb_lens_protocol.h"

namespace camhead::hal::lens {

struct UsbLensConfig {
  std::uint16_t vid = kUsbLensVendorId;
  std::uint16_t pid = kUsbLensProductId;
  // Only the board with this iSerialNumber; without, the first board found.
  std::optional<std::string> serial;
  // Deliver an axis only once the board reports it homed (its count is
  // absolute). Boards with absolute encoders always report homed; set false
  // for an incremental board without an index, at your own risk.
  bool require_homed = true;
  // Readings held between two polls; beyond it the oldest are dropped and
  // counted as lost. 4096 are four seconds at 1 kHz.
  std::size_t queue_capacity = 4096;
  // How often to enumerate again while no board is connected: a quarter
  // second, as the V4L2 camera and output reopen, so that a board plugged
  // back streams within half a second of its enumeration where no hotplug
  // event comes (no udevd: the lab's usb_replug_100 measures it).
  std::chrono::milliseconds rescan_interval{250};
};

// "usb 1209:0001", or "usb 1209:0001 serial LE000042": the source's name()
// and the prefix of every status detail.
[[nodiscard]] std::string usb_lens_name(const UsbLensConfig &config);

// The real board through libusb-1.0. Does not throw for an absent board, a
// board without permission, or a system without USB: status().detail says
// what it is waiting for.
[[nodiscard]] std::unique_ptr<LensEncoder> open_usb_lens(const UsbLensConfig &config = {});

} // namespace camhead::hal::lens
