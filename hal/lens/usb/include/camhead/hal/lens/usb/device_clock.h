// Maps the lens board's 32-bit microsecond clock to this host's
// CLOCK_MONOTONIC (docs/usb-lens-protocol.md, section 5).
//
// Why not simply stamp reports when they arrive: the arrival time carries the
// USB polling interval, the host controller's and the kernel's scheduling,
// and whatever kept the host busy, a jitter of 0.1-several ms that would land
// on the rendered focus. The board latched its counts at a known instant of
// its own clock; only the offset (and slow drift) between the two clocks is
// unknown, and it can be estimated well:
//
//   d = receive_ns - device_us * 1000 = offset + delay,  delay >= 0.
//
// The delay is one-sided: most reports arrive close to its floor, some late,
// none early. So the minimum of d over a window is the offset plus the
// floor of the delay, untouched by the jitter that a mean would absorb. To
// follow drift (crystals differ by up to ~100 ppm), the minimum is kept per
// block of device time and a line is fitted through the last blocks' minima.
// The floor of the delay that remains is a constant of the board and its
// bus: lens_control's per-source delay removes it.
//
// Wrap: the 32-bit device time wraps every 71.6 minutes; it is unwrapped by
// taking each step from the previous report as a signed 32-bit number.
//
// Thread safety: none; the transport thread that receives reports owns it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace camhead::hal::lens {

struct ClockMapperParams {
  std::int64_t block_us = 500'000; // device time per minimum block
  std::size_t max_blocks = 16;     // blocks in the fit: 8 s by default
  double max_skew_ppm = 500.0;     // a fitted drift beyond this is clamped
  // d this far from the estimate means the device clock jumped (a firmware
  // reset that kept USB up, a silence past the unwrap range)...
  std::int64_t resync_ns = 1'000'000'000;
  // ... when it happens this many reports in a row. Fewer are late reports
  // after a host stall: mapped as usual, kept out of the estimate.
  int resync_after = 8;
};

class DeviceClockMapper {
public:
  explicit DeviceClockMapper(ClockMapperParams p = {});

  // One report's device time and its CLOCK_MONOTONIC receive time, in
  // arrival order. Returns the CLOCK_MONOTONIC instant the counts were
  // latched (plus the delay floor): never later than receive_ns, and strictly
  // increasing from one call to the next while the device time advances.
  [[nodiscard]] std::int64_t map(std::uint32_t device_time_us, std::int64_t receive_ns);

  // Start over: the next report is a first one (call on every reconnect).
  void reset();

  // The fitted drift of the device clock, for monitoring and tests (ppm,
  // positive when the device clock runs slow against the host's).
  [[nodiscard]] double skew_ppm() const { return slope_ * 1000.0; }
  [[nodiscard]] std::int64_t unwrapped_us() const { return device_us_; }
  [[nodiscard]] std::uint64_t resyncs() const { return resyncs_; }

private:
  // The lowest d seen in one block of device time, and the span of device
  // time the block's reports covered.
  struct Floor {
    std::int64_t device_us = 0;
    std::int64_t d_ns = 0;
    std::int64_t first_us = 0, last_us = 0;
  };

  void start(std::uint32_t raw, std::int64_t receive_ns);
  [[nodiscard]] std::int64_t estimate_at(std::int64_t device_us) const;
  void add_to_estimate(std::int64_t device_us, std::int64_t d_ns);
  void fit();

  ClockMapperParams p_;
  bool primed_ = false;
  std::uint32_t last_raw_ = 0;
  std::int64_t device_us_ = 0; // unwrapped device time of the newest report
  std::int64_t last_out_ns_ = 0;
  int outliers_in_a_row_ = 0;
  std::uint64_t resyncs_ = 0;

  std::int64_t origin_us_ = 0; // blocks count from the first report
  std::int64_t block_index_ = 0;
  Floor current_;           // the block being filled
  std::vector<Floor> done_; // completed blocks, oldest first, at most max_blocks

  // offset(t) = base_ns_ + intercept_ + slope_ * (t - ref_us_) once two
  // blocks are done; before that the lowest d so far (slope 0).
  bool fitted_ = false;
  double intercept_ = 0.0, slope_ = 0.0; // ns, ns per us
  std::int64_t ref_us_ = 0, base_ns_ = 0;
};

} // namespace camhead::hal::lens
