// The shared middle of the USB lens backend, identical for the real board
// and its simulated twin: a transport (libusb, or the simulated board) feeds
// a UsbLensSession through UsbLensLink; the session parses, maps the clock,
// counts loss and malformed reports, runs the connected/reconnect state
// machine and queues readings; UsbLensEncoder is the LensEncoder on top.
//
// Accounting: every report the board latched ends up in exactly one of
// readings (delivered), malformed (rejected by the parser; its gap in the
// sequence is not counted again) or lost (a sequence gap, or dropped from a
// full queue), as long as the board stays connected and its axes usable.
//
// Thread safety: the UsbLensLink calls come from one transport thread at a
// time and own the parser state (clock mapper, sequence tracker) without a
// lock; the queue and the status sit behind one mutex, taken briefly by the
// transport thread per report and by poll()/status().
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "camhead/hal/lens/lens_encoder.h"
#include "camhead/hal/lens/usb/device_clock.h"
#include "camhead/hal/lens/usb/sequence_tracker.h"
#include "camhead/hal/lens/usb/usb_lens.h"
#include "camhead/hal/lens/usb/usb_lens_link.h"

namespace camhead::hal::lens::detail {

class UsbLensSession final : public UsbLensLink {
public:
  UsbLensSession(std::string name, const UsbLensConfig &config);

  // UsbLensLink: the transport thread.
  void device_arrived(const std::string &description) override;
  void report_received(std::span<const std::uint8_t> bytes, std::int64_t receive_ns) override;
  void report_rejected(const std::string &reason) override;
  void device_left(const std::string &reason) override;
  void waiting(const std::string &reason) override;

  // LensEncoder: poll from the lens thread, status and name from any.
  void poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out);
  [[nodiscard]] EncoderStatus status() const;
  [[nodiscard]] const std::string &name() const { return name_; }

private:
  // Which fitted axes are unusable and why ("focus not homed, zoom encoder
  // fault"); empty when all fitted axes are usable.
  [[nodiscard]] std::string axis_problems(std::uint8_t axes, std::uint16_t status) const;
  void set_state(std::string state); // under mutex_
  void update_detail();              // under mutex_

  const std::string name_;
  const bool require_homed_;

  // Transport thread only.
  DeviceClockMapper clock_;
  SequenceTracker sequence_;
  bool have_flags_ = false;
  std::uint8_t last_axes_ = 0;
  std::uint16_t last_status_ = 0;
  std::uint64_t malformed_since_valid_ = 0;

  // Shared with the polling thread.
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<EncoderReading> ring_; // fixed capacity, no allocation per report
  std::size_t head_ = 0, size_ = 0;
  EncoderStatus status_;
  bool ever_connected_ = false;
  std::string state_, axis_note_, last_problem_;
};

// A transport is whatever feeds a session; destroying it stops its thread.
class UsbLensTransport {
public:
  virtual ~UsbLensTransport() = default;
};

class UsbLensEncoder final : public LensEncoder {
public:
  using MakeTransport = std::function<std::unique_ptr<UsbLensTransport>(UsbLensLink &)>;

  UsbLensEncoder(std::string name, const UsbLensConfig &config, const MakeTransport &make);
  ~UsbLensEncoder() override;

  [[nodiscard]] std::string name() const override { return session_.name(); }
  void poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) override {
    session_.poll(timeout, out);
  }
  [[nodiscard]] EncoderStatus status() const override { return session_.status(); }

private:
  UsbLensSession session_;
  std::unique_ptr<UsbLensTransport> transport_; // after session_: stops before it dies
};

} // namespace camhead::hal::lens::detail
