// What a lens-board transport tells the code above it: the seam between the
// parts of the USB lens backend that differ (libusb, or the simulated board)
// and the parts that must not (report parsing, clock mapping, loss and
// malformed accounting, the connected/reconnect state machine, the reading
// queue behind poll()).
//
// A transport calls these from one thread at a time (its event thread, or
// the test thread that steps a simulated board), in the order things happened:
// device_arrived before the device's first report, device_left after its
// last. The implementation behind them is thread-safe against the thread
// that polls.
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace camhead::hal::lens {

class UsbLensLink {
public:
  virtual ~UsbLensLink() = default;

  // The board is open and its reports are about to flow. `description` is
  // for the status text: "bus 1 device 4, serial LE000042, firmware 1.2.3".
  virtual void device_arrived(const std::string &description) = 0;

  // One completed transfer and the CLOCK_MONOTONIC instant it completed.
  // Any bytes: what is not a valid report is counted malformed and dropped.
  virtual void report_received(std::span<const std::uint8_t> bytes, std::int64_t receive_ns) = 0;

  // A transfer that could not be a report (longer than a packet): counted
  // malformed.
  virtual void report_rejected(const std::string &reason) = 0;

  // The board is closed: "device went away (LIBUSB_TRANSFER_NO_DEVICE)".
  virtual void device_left(const std::string &reason) = 0;

  // While no board is open, what the transport is waiting for: "not
  // connected", "cannot open bus 1 device 4: LIBUSB_ERROR_ACCESS ...".
  virtual void waiting(const std::string &reason) = 0;
};

} // namespace camhead::hal::lens
