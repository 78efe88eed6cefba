// The shared middle of the USB lens backend; see usb_lens_session.h.
#include "usb_lens_session.h"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <utility>

#include "camhead/hal/lens/usb/usb_lens_protocol.h"

namespace camhead::hal::lens {

std::string usb_lens_name(const UsbLensConfig &config) {
  char ids[16];
  std::snprintf(ids, sizeof ids, "%04x:%04x", config.vid, config.pid);
  std::string name = std::string{"usb "} + ids;
  if (config.serial) {
    name += " serial " + *config.serial;
  }
  return name;
}

namespace detail {
namespace {

struct AxisBits {
  const char *name;
  std::uint8_t fitted;
  std::uint16_t homed, fault;
  std::optional<std::int32_t> EncoderReading::*field;
};

constexpr AxisBits kAxes[] = {
    {"focus", kAxisFocus, kStatusFocusHomed, kStatusFocusFault, &EncoderReading::focus},
    {"iris", kAxisIris, kStatusIrisHomed, kStatusIrisFault, &EncoderReading::iris},
    {"zoom", kAxisZoom, kStatusZoomHomed, kStatusZoomFault, &EncoderReading::zoom},
};

} // namespace

UsbLensSession::UsbLensSession(std::string name, const UsbLensConfig &config)
    : name_(std::move(name)), require_homed_(config.require_homed),
      ring_(std::max<std::size_t>(config.queue_capacity, 1)) {
  std::lock_guard lock(mutex_);
  set_state("not connected, waiting");
}

void UsbLensSession::set_state(std::string state) {
  state_ = std::move(state);
  update_detail();
}

void UsbLensSession::update_detail() {
  status_.detail = name_ + ": " + state_;
  if (!axis_note_.empty()) {
    status_.detail += "; " + axis_note_;
  }
  if (!last_problem_.empty()) {
    status_.detail += "; last problem: " + last_problem_;
  }
}

std::string UsbLensSession::axis_problems(std::uint8_t axes, std::uint16_t status) const {
  std::string text;
  for (const AxisBits &a : kAxes) {
    if ((axes & a.fitted) == 0) {
      continue;
    }
    const char *problem = (status & a.fault) != 0                     ? " encoder fault"
                          : require_homed_ && (status & a.homed) == 0 ? " not homed"
                                                                      : nullptr;
    if (problem != nullptr) {
      text += (text.empty() ? "" : ", ") + std::string{a.name} + problem;
    }
  }
  return text;
}

void UsbLensSession::device_arrived(const std::string &description) {
  // A board that was away has restarted its clock and its sequence.
  clock_.reset();
  sequence_.reset();
  have_flags_ = false;
  malformed_since_valid_ = 0;
  std::lock_guard lock(mutex_);
  if (ever_connected_) {
    ++status_.reconnects;
  }
  ever_connected_ = true;
  status_.connected = true;
  axis_note_.clear();
  set_state("connected (" + description + ")");
}

void UsbLensSession::device_left(const std::string &reason) {
  std::lock_guard lock(mutex_);
  if (!status_.connected) {
    return;
  }
  status_.connected = false;
  axis_note_.clear();
  set_state(reason + ", waiting");
}

void UsbLensSession::waiting(const std::string &reason) {
  std::lock_guard lock(mutex_);
  if (status_.connected) {
    return; // a transport only waits while nothing is open
  }
  const std::string state = reason + ", waiting";
  if (state != state_) {
    set_state(state);
  }
}

void UsbLensSession::report_rejected(const std::string &reason) {
  ++malformed_since_valid_; // transport thread, like the parser state
  std::lock_guard lock(mutex_);
  ++status_.malformed;
  last_problem_ = reason;
  update_detail();
}

void UsbLensSession::report_received(std::span<const std::uint8_t> bytes, std::int64_t receive_ns) {
  ReportParseResult parsed = parse_report(bytes);
  if (!parsed) {
    report_rejected(parsed.detail);
    return;
  }
  const LensReport &r = *parsed.report;
  const SequenceTracker::Step step = sequence_.push(r.sequence);
  // A rejected report leaves a gap in the sequence too; it is counted once,
  // as malformed, so that readings + malformed + lost add up to what the
  // board sent.
  const std::uint64_t lost =
      step.lost > malformed_since_valid_ ? step.lost - malformed_since_valid_ : 0;
  malformed_since_valid_ = 0;
  EncoderReading reading;
  reading.t_ns = clock_.map(r.device_time_us, receive_ns);
  bool any_axis = false;
  for (const AxisBits &a : kAxes) {
    const bool usable = (r.axes & a.fitted) != 0 && (r.status & a.fault) == 0 &&
                        (!require_homed_ || (r.status & a.homed) != 0);
    if (usable) {
      const std::int32_t count = a.fitted == kAxisFocus  ? r.focus
                                 : a.fitted == kAxisIris ? r.iris
                                                         : r.zoom;
      reading.*a.field = count;
      any_axis = true;
    }
  }
  // The flags rarely change; describe them only when they do, so that the
  // per-report path builds no strings.
  const bool flags_changed = !have_flags_ || r.axes != last_axes_ || r.status != last_status_;
  std::string note;
  if (flags_changed) {
    note = axis_problems(r.axes, r.status);
    have_flags_ = true;
    last_axes_ = r.axes;
    last_status_ = r.status;
  }

  {
    std::lock_guard lock(mutex_);
    status_.lost += lost;
    if (flags_changed) {
      axis_note_ = std::move(note);
      update_detail();
    }
    // A report whose every axis is unusable says nothing about the lens:
    // the status text says why, and no reading goes out.
    if (!any_axis) {
      return;
    }
    if (size_ == ring_.size()) {
      head_ = (head_ + 1) % ring_.size(); // drop the oldest
      --size_;
      ++status_.lost;
    }
    ring_[(head_ + size_) % ring_.size()] = reading;
    ++size_;
  }
  ready_.notify_one();
}

void UsbLensSession::poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) {
  std::unique_lock lock(mutex_);
  // wait_for keeps its own deadline across spurious wake-ups: never longer
  // than the timeout, whatever the transport is doing.
  ready_.wait_for(lock, timeout, [this] { return size_ > 0; });
  out.reserve(out.size() + size_);
  for (; size_ > 0; --size_) {
    out.push_back(ring_[head_]);
    head_ = (head_ + 1) % ring_.size();
    ++status_.readings;
  }
}

EncoderStatus UsbLensSession::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

UsbLensEncoder::UsbLensEncoder(std::string name, const UsbLensConfig &config,
                               const MakeTransport &make)
    : session_(std::move(name), config), transport_(make(session_)) {}

UsbLensEncoder::~UsbLensEncoder() {
  transport_.reset(); // no transport thread may outlive the session it feeds
}

} // namespace detail
} // namespace camhead::hal::lens
