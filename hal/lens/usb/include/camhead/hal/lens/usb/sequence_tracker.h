// Counting lost reports from a 32-bit wrapping sequence number.
//
// The board increments the sequence once per latched sample, whether or not
// the sample reached the host (docs/usb-lens-protocol.md, section 3), so a
// gap between two received reports is exactly the number of samples lost on
// the way, wherever they were lost: in the board's one-deep endpoint buffer,
// on the bus, or in a host that did not resubmit a transfer in time.
//
// What is not loss: a jump backwards (the board restarted without the host
// seeing it leave) and a jump forwards by more than kMaxPlausibleGap (a restart
// that happened to land ahead). Both restart the count from the new number.
// A reconnect resets the tracker: what the board sent while unplugged is not
// counted as lost, the reconnect counter covers it.
//
// Thread safety: none; the transport thread that receives reports owns it.
#pragma once

#include <cstdint>

namespace camhead::hal::lens {

class SequenceTracker {
public:
  // 65536 reports are a minute at 1 kHz: no real gap in a stream that stayed
  // connected is that long.
  static constexpr std::uint32_t kMaxPlausibleGap = 65536;

  struct Step {
    std::uint32_t lost = 0; // reports missing just before this one
    bool resync = false;    // this one restarted the count (see above)
  };

  // The sequence number of the next received report, in arrival order.
  Step push(std::uint32_t sequence);
  // Forget the previous report: the next push is a first one.
  void reset() { primed_ = false; }

  [[nodiscard]] std::uint64_t lost() const { return lost_; }
  [[nodiscard]] std::uint64_t resyncs() const { return resyncs_; }

private:
  bool primed_ = false;
  std::uint32_t last_ = 0;
  std::uint64_t lost_ = 0, resyncs_ = 0;
};

} // namespace camhead::hal::lens
