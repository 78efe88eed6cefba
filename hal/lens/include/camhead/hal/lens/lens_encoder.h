// The one interface every lens-encoder backend implements: USB encoder board,
// GPIO quadrature, network lens data (FreeD, OpenTrackIO), recorded trace, and
// the simulated twin of each. A board file chooses which (pipeline/ builds
// them); nothing above hal/ knows which one it is talking to.
//
// Pull model: the lens thread calls poll() in a loop. A backend never blocks
// longer than the timeout it is given, never throws for a device that went
// away (it reports `connected = false` and keeps trying), and counts what it
// had to drop. That is what keeps the pipeline running through an unplug.
//
// hal/ knows nothing of lens_control: readings are raw counts in the device's
// own units. pipeline/ turns them into lens_control::EncoderSample.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace camhead::hal::lens {

// The camera's pose as a tracking source sends it, in the protocol's own
// axes and angles: X, Y, Z in metres and pan, tilt, roll in degrees, whose
// directions and order each protocol defines (FreeD's and OpenTrackIO's
// differ); pipeline/tracking turns them into camhead's world.
struct TrackedPose {
  double x_m = 0.0, y_m = 0.0, z_m = 0.0;
  double pan_deg = 0.0, tilt_deg = 0.0, roll_deg = 0.0;

  bool operator==(const TrackedPose &) const = default;
};

// One reading of whichever axes the source carries. Counts are the encoder's
// raw units (a quadrature position, a USB board's 32-bit count, FreeD's
// 24-bit value, OpenTrackIO's normalised encoder scaled by kNormalisedCounts).
struct EncoderReading {
  // CLOCK_MONOTONIC nanoseconds at which the counts were valid: the device's
  // own timestamp mapped to this host where the source has one, else the
  // receive time. Per-source delay correction happens in lens_control.
  std::int64_t t_ns = 0;
  std::optional<std::int32_t> focus, iris, zoom;

  // Calibrated values, where the source already knows them (OpenTrackIO's
  // focusDistance / fStop / pinholeFocalLength, a recorded trace).
  std::optional<double> focus_distance_m, f_stop, focal_length_mm;

  // The camera's pose, where the source tracks it (FreeD, OpenTrackIO's
  // transforms).
  std::optional<TrackedPose> pose;

  bool operator==(const EncoderReading &) const = default;
};

// OpenTrackIO sends encoders normalised to [0, 1]; camhead maps them to
// counts 0..kNormalisedCounts so that one profile format serves every source.
inline constexpr std::int32_t kNormalisedCounts = 65535;

// Health of one source, for `camhead lens monitor`, statistics and logs.
struct EncoderStatus {
  bool connected = false;
  std::uint64_t readings = 0;     // delivered through poll()
  std::uint64_t malformed = 0;    // reports/datagrams rejected (checksum, length, ...)
  std::uint64_t lost = 0;         // gaps in sequence numbers, queue overflows
  std::uint64_t missed_edges = 0; // quadrature: illegal transitions (both lines changed)
  std::uint64_t reconnects = 0;   // device came back after going away
  std::string detail;             // last error or state, human readable, names the device
};

class LensEncoder {
public:
  virtual ~LensEncoder() = default;
  LensEncoder() = default;
  LensEncoder(const LensEncoder &) = delete;
  LensEncoder &operator=(const LensEncoder &) = delete;

  // Who this is, for messages: "usb 1209:ca3e serial 0042", "gpio gpiochip0",
  // "freed udp :40000", "trace scenes/lenses/pull_focus.csv".
  [[nodiscard]] virtual std::string name() const = 0;

  // Waits at most `timeout` for new readings and appends them to `out`,
  // oldest first. Returns without waiting when readings are already queued.
  virtual void poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) = 0;

  [[nodiscard]] virtual EncoderStatus status() const = 0;
};

} // namespace camhead::hal::lens
