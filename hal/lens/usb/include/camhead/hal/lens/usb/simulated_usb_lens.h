// The simulated twin of the USB lens board: a board model that latches
// samples from a trajectory on its own drifting clock and delivers the very
// bytes the real board sends, with a transport delay, to the same shared code
// the libusb backend feeds (usb_lens_link.h). Parsing, clock mapping, loss and
// malformed accounting and the reconnect state machine are therefore the
// real ones; only the transport below them is fake.
//
// Faults on request: drop the next n reports (a sequence gap: lost), corrupt
// the next n (one flipped bit after the CRC: malformed), unplug and replug
// (the board powers down: on replug its clock and sequence start over, as a
// bus-powered board's do).
//
// Time: the board lives on a host timeline in CLOCK_MONOTONIC nanoseconds.
// With SimulatedDrive::manual nothing moves until the caller calls
// advance_to(), which delivers every report that has arrived by then on the
// calling thread: deterministic, for tests. With SimulatedDrive::realtime a
// thread of the source advances the board to CLOCK_MONOTONIC every
// millisecond, for `camhead run --board sim`.
//
// Thread safety: every member of SimulatedUsbLensBoard may be called from any
// thread (one lock inside). The board's calls into its link happen under
// that lock, on the thread that advanced or unplugged it.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "camhead/hal/lens/lens_encoder.h"
#include "camhead/hal/lens/usb/lens_ramp.h"
#include "camhead/hal/lens/usb/usb_lens.h"
#include "camhead/hal/lens/usb/usb_lens_link.h"
#include "camhead/hal/lens/usb/usb_lens_protocol.h"

namespace camhead::hal::lens {

// Counts of sample `index` since power-up, `seconds` of device time after it.
using LensTrajectory = std::function<LensAxes(std::uint32_t index, double seconds)>;

struct SimulatedUsbLensOptions {
  double rate_hz = 500.0;    // samples latched per second of host time
  LensTrajectory trajectory; // empty: LensRamp{}
  std::uint8_t axes = kAxesAll;
  std::uint16_t status = kStatusAllHomed;
  std::uint32_t clock_start_us = 0;  // device time at each power-up
  double clock_skew_ppm = 0.0;       // > 0: the device clock runs fast
  std::int64_t latency_ns = 250'000; // latch -> host receipt, fixed part
  std::int64_t jitter_ns = 0;        // plus uniform 0..jitter_ns per report
  std::uint64_t seed = 1;            // of the jitter
  std::uint32_t first_sequence = 0;  // at each power-up
  std::string serial = "SIM0001";
  std::uint32_t firmware_version = 0x010000; // 1.0.0
  bool plugged = true;                       // present at the start
};

class SimulatedUsbLensBoard {
public:
  // The board powers up (if plugged) at host time `start_ns`; empty: now.
  explicit SimulatedUsbLensBoard(SimulatedUsbLensOptions options = {},
                                 std::optional<std::int64_t> start_ns = std::nullopt);
  SimulatedUsbLensBoard(const SimulatedUsbLensBoard &) = delete;
  SimulatedUsbLensBoard &operator=(const SimulatedUsbLensBoard &) = delete;

  // Delivers, in order, every report that reaches the host by `host_ns`.
  // Time only moves forward: an earlier host_ns does nothing.
  void advance_to(std::int64_t host_ns);

  // Faults. drop/corrupt apply to the next reports latched from now on.
  void drop_next(unsigned reports);
  void corrupt_next(unsigned reports);
  void set_status(std::uint16_t status);
  // At the board's current time; reports latched but not yet arrived are
  // lost with the cable. Unplugging an unplugged board does nothing, and
  // likewise for replug.
  void unplug();
  void replug();

  struct Counters {
    std::uint64_t latched = 0;   // samples, delivered or not
    std::uint64_t delivered = 0; // reports handed to the link, corrupted ones included
    std::uint64_t dropped = 0, corrupted = 0;
    std::uint64_t power_ups = 0;
  };
  [[nodiscard]] Counters counters() const;
  [[nodiscard]] std::int64_t now_ns() const;
  [[nodiscard]] bool plugged() const;
  [[nodiscard]] const std::string &serial() const { return options_.serial; }

  // The link reports go to; nullptr detaches. Attaching to a plugged board
  // announces it at once (device_arrived). open_simulated_usb_lens does this.
  void attach(UsbLensLink *link);

private:
  struct Pending {
    std::int64_t arrival_ns = 0;
    bool valid = false;
  };

  [[nodiscard]] std::int64_t latch_ns(std::uint64_t index) const;
  [[nodiscard]] std::uint32_t device_time_us(std::int64_t host_ns) const;
  [[nodiscard]] std::int64_t next_arrival_ns();
  void deliver_next();
  void power_up();
  [[nodiscard]] std::string description() const;

  const SimulatedUsbLensOptions options_;
  const LensTrajectory trajectory_;
  const std::int64_t period_ns_;

  mutable std::mutex mutex_;
  UsbLensLink *link_ = nullptr;
  bool plugged_ = false;
  std::int64_t now_ns_ = 0;
  std::int64_t power_up_ns_ = 0;
  std::uint64_t index_ = 0; // next sample since power-up
  std::int64_t last_arrival_ns_ = 0;
  Pending next_;
  unsigned drop_ = 0, corrupt_ = 0;
  std::uint16_t status_ = 0;
  std::uint64_t rng_ = 0;
  std::uint32_t corrupt_bit_ = 0;
  Counters counters_;
};

enum class SimulatedDrive { manual, realtime };

// The simulated board as a LensEncoder, through the same shared code as
// open_usb_lens(). The name is "simulated " + usb_lens_name(config). A board
// whose serial differs from config.serial is never announced (the source
// waits, as the real one would).
[[nodiscard]] std::unique_ptr<LensEncoder>
open_simulated_usb_lens(std::shared_ptr<SimulatedUsbLensBoard> board,
                        const UsbLensConfig &config = {},
                        SimulatedDrive drive = SimulatedDrive::realtime);

} // namespace camhead::hal::lens
