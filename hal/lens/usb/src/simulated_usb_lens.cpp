// The simulated lens board and its transport; see simulated_usb_lens.h.
#include "camhead/hal/lens/usb/simulated_usb_lens.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <thread>
#include <utility>

#include "camhead/hal/lens/monotonic_clock.h"
#include "usb_lens_session.h"

namespace camhead::hal::lens {
namespace {

// splitmix64: a tiny, seedable generator, so that a jittery board replays the
// same delays run after run.
std::uint64_t next_random(std::uint64_t &state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

LensTrajectory default_trajectory(LensTrajectory given) {
  if (given) {
    return given;
  }
  return [ramp = LensRamp{}](std::uint32_t index, double) { return ramp.at(index); };
}

} // namespace

SimulatedUsbLensBoard::SimulatedUsbLensBoard(SimulatedUsbLensOptions options,
                                             std::optional<std::int64_t> start_ns)
    : options_(std::move(options)), trajectory_(default_trajectory(options_.trajectory)),
      period_ns_(std::max<std::int64_t>(1, std::llround(1e9 / std::max(options_.rate_hz, 1e-3)))) {
  now_ns_ = start_ns.value_or(monotonic_ns());
  status_ = options_.status;
  rng_ = options_.seed;
  if (options_.plugged) {
    power_up();
  }
}

void SimulatedUsbLensBoard::power_up() {
  plugged_ = true;
  power_up_ns_ = now_ns_;
  index_ = 0;
  last_arrival_ns_ = now_ns_;
  next_.valid = false;
  ++counters_.power_ups;
}

std::string SimulatedUsbLensBoard::description() const {
  return "simulated, serial " + options_.serial + ", firmware " +
         firmware_version_string(options_.firmware_version);
}

std::int64_t SimulatedUsbLensBoard::latch_ns(std::uint64_t index) const {
  return power_up_ns_ + static_cast<std::int64_t>(index) * period_ns_;
}

std::uint32_t SimulatedUsbLensBoard::device_time_us(std::int64_t host_ns) const {
  const double elapsed_us =
      static_cast<double>(host_ns - power_up_ns_) * (1.0 + options_.clock_skew_ppm * 1e-6) / 1e3;
  // Modulo 2^32 on purpose: the real board's counter wraps too.
  return options_.clock_start_us +
         static_cast<std::uint32_t>(static_cast<std::uint64_t>(std::llround(elapsed_us)));
}

std::int64_t SimulatedUsbLensBoard::next_arrival_ns() {
  if (!next_.valid) {
    std::int64_t jitter = 0;
    if (options_.jitter_ns > 0) {
      jitter = static_cast<std::int64_t>(next_random(rng_) %
                                         static_cast<std::uint64_t>(options_.jitter_ns + 1));
    }
    // One pipe: a report never overtakes the one before it.
    next_.arrival_ns = std::max(last_arrival_ns_, latch_ns(index_) + options_.latency_ns + jitter);
    next_.valid = true;
  }
  return next_.arrival_ns;
}

void SimulatedUsbLensBoard::deliver_next() {
  const std::int64_t latched = latch_ns(index_);
  const auto index = static_cast<std::uint32_t>(index_);
  const double seconds = static_cast<double>(latched - power_up_ns_) * 1e-9;
  const LensAxes axes = trajectory_(index, seconds);

  LensReport report;
  report.axes = options_.axes;
  report.sequence = options_.first_sequence + index;
  report.device_time_us = device_time_us(latched);
  report.focus = axes.focus;
  report.iris = axes.iris;
  report.zoom = axes.zoom;
  report.status = status_;
  auto bytes = encode_report(report);

  last_arrival_ns_ = next_.arrival_ns;
  next_.valid = false;
  ++index_;
  ++counters_.latched;
  if (drop_ > 0) {
    --drop_;
    ++counters_.dropped;
    return;
  }
  if (corrupt_ > 0) {
    --corrupt_;
    ++counters_.corrupted;
    // Walk the flipped bit through the report, so that a long run of
    // corruption touches every field and the CRC itself.
    const std::uint32_t bit = corrupt_bit_++ % (kUsbLensReportSize * 8);
    bytes[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
  }
  ++counters_.delivered;
  if (link_ != nullptr) {
    link_->report_received(bytes, last_arrival_ns_);
  }
}

void SimulatedUsbLensBoard::advance_to(std::int64_t host_ns) {
  std::lock_guard lock(mutex_);
  while (plugged_ && next_arrival_ns() <= host_ns) {
    now_ns_ = std::max(now_ns_, next_.arrival_ns);
    deliver_next();
  }
  now_ns_ = std::max(now_ns_, host_ns);
}

void SimulatedUsbLensBoard::drop_next(unsigned reports) {
  std::lock_guard lock(mutex_);
  drop_ += reports;
}

void SimulatedUsbLensBoard::corrupt_next(unsigned reports) {
  std::lock_guard lock(mutex_);
  corrupt_ += reports;
}

void SimulatedUsbLensBoard::set_status(std::uint16_t status) {
  std::lock_guard lock(mutex_);
  status_ = status;
}

void SimulatedUsbLensBoard::unplug() {
  std::lock_guard lock(mutex_);
  if (!plugged_) {
    return;
  }
  plugged_ = false;
  next_.valid = false;
  if (link_ != nullptr) {
    link_->device_left("device went away (simulated unplug)");
  }
}

void SimulatedUsbLensBoard::replug() {
  std::lock_guard lock(mutex_);
  if (plugged_) {
    return;
  }
  power_up();
  if (link_ != nullptr) {
    link_->device_arrived(description());
  }
}

void SimulatedUsbLensBoard::attach(UsbLensLink *link) {
  std::lock_guard lock(mutex_);
  link_ = link;
  if (link_ != nullptr) {
    if (plugged_) {
      link_->device_arrived(description());
    } else {
      link_->waiting("not connected");
    }
  }
}

SimulatedUsbLensBoard::Counters SimulatedUsbLensBoard::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

std::int64_t SimulatedUsbLensBoard::now_ns() const {
  std::lock_guard lock(mutex_);
  return now_ns_;
}

bool SimulatedUsbLensBoard::plugged() const {
  std::lock_guard lock(mutex_);
  return plugged_;
}

namespace {

// The fake transport: attaches the session to the board and, in real time,
// moves the board along CLOCK_MONOTONIC from a thread of its own, as the
// libusb transport's event thread delivers the real board's transfers.
class SimulatedTransport final : public detail::UsbLensTransport {
public:
  SimulatedTransport(std::shared_ptr<SimulatedUsbLensBoard> board, UsbLensLink &link,
                     const UsbLensConfig &config, SimulatedDrive drive)
      : board_(std::move(board)) {
    if (config.serial && *config.serial != board_->serial()) {
      link.waiting("found only serial " + board_->serial());
      return; // not our board: never attached, the source waits
    }
    board_->attach(&link);
    attached_ = true;
    if (drive == SimulatedDrive::realtime) {
      thread_ = std::thread([this] { run(); });
    }
  }

  ~SimulatedTransport() override {
    stop_ = true;
    if (thread_.joinable()) {
      thread_.join();
    }
    if (attached_) {
      board_->attach(nullptr);
    }
  }

  SimulatedTransport(const SimulatedTransport &) = delete;
  SimulatedTransport &operator=(const SimulatedTransport &) = delete;

private:
  void run() {
    while (!stop_) {
      board_->advance_to(monotonic_ns());
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }

  std::shared_ptr<SimulatedUsbLensBoard> board_;
  bool attached_ = false;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

} // namespace

std::unique_ptr<LensEncoder> open_simulated_usb_lens(std::shared_ptr<SimulatedUsbLensBoard> board,
                                                     const UsbLensConfig &config,
                                                     SimulatedDrive drive) {
  return std::make_unique<detail::UsbLensEncoder>(
      "simulated " + usb_lens_name(config), config,
      [&](UsbLensLink &link) -> std::unique_ptr<detail::UsbLensTransport> {
        return std::make_unique<SimulatedTransport>(std::move(board), link, config, drive);
      });
}

} // namespace camhead::hal::lens
