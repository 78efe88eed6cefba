// The real board through libusb-1.0: one event thread that finds the board,
// opens it, keeps interrupt transfers queued on its endpoint and hands every
// completed transfer to the shared session (usb_lens_session.h). See
// usb_lens.h for the behaviour and docs/usb-lens-protocol.md for the board.
//
// Every libusb call, callback included, happens on the event thread, so the
// members below need no lock; the session behind UsbLensLink is the only
// thing shared with the polling thread.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "camhead/hal/lens/usb/usb_lens.h"
#include "camhead/hal/lens/usb/usb_lens_protocol.h"
#include "libusb_handles.h"
#include "usb_lens_session.h"

namespace camhead::hal::lens {
namespace detail {
namespace {

using Clock = std::chrono::steady_clock;

// Transfers kept queued: while one completes and is resubmitted, the others
// keep the endpoint polled, so a 1 kHz board loses nothing to resubmission.
constexpr std::size_t kTransfers = 4;
// How long one turn of the event loop may block: bounds the destructor's wait.
constexpr long kEventSliceUs = 50'000;
// Transfer errors in a row (not "no device") before the board is closed and
// opened again: a board that answers nothing but errors is as good as gone.
constexpr int kMaxErrorsInARow = 20;
// Cancelled transfers normally return within a few ms; past this they are
// abandoned (leaked) rather than freed under libusb's feet.
constexpr auto kCancelWait = std::chrono::seconds(2);

class LibusbTransport final : public UsbLensTransport {
public:
  LibusbTransport(const UsbLensConfig &config, UsbLensLink &link)
      : config_(config), link_(link), thread_([this] { run(); }) {}

  ~LibusbTransport() override {
    stop_ = true;
    thread_.join();
  }

  LibusbTransport(const LibusbTransport &) = delete;
  LibusbTransport &operator=(const LibusbTransport &) = delete;

private:
  struct Slot {
    // Allocated when a device is opened, freed when it is closed (see
    // close_device): never outlives the handle or the context.
    TransferPtr transfer;
    std::vector<unsigned char> buffer;
    bool in_flight = false;
  };

  void run();
  bool init_context();
  void drop_context();
  void scan_device_list();
  void try_open(libusb_device *dev);
  void submit(Slot &slot);
  void close_device(const std::string &reason);
  void mark_gone(std::string reason);
  void on_transfer(libusb_transfer *transfer);

  static void LIBUSB_CALL transfer_callback(libusb_transfer *transfer) {
    static_cast<LibusbTransport *>(transfer->user_data)->on_transfer(transfer);
  }
  static int LIBUSB_CALL hotplug_callback(libusb_context *, libusb_device *dev,
                                          libusb_hotplug_event event, void *user) {
    auto *self = static_cast<LibusbTransport *>(user);
    if (event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED) {
      self->arrivals_.emplace_back(libusb().ref_device(dev));
    } else if (self->handle_ && libusb().get_device(self->handle_.get()) == dev) {
      self->mark_gone("device went away (hotplug)");
    }
    return 0; // stay registered
  }

  const UsbLensConfig config_;
  UsbLensLink &link_;
  std::atomic<bool> stop_{false};

  // Event thread only.
  ContextPtr ctx_;
  bool hotplug_ = false;
  libusb_hotplug_callback_handle hotplug_handle_{};
  std::vector<DevicePtr> arrivals_; // from the hotplug callback or a scan
  Clock::time_point next_rescan_{};
  HandlePtr handle_;
  LensInterface lens_{};
  std::array<Slot, kTransfers> slots_;
  bool gone_ = false, halted_ = false;
  std::string gone_reason_;
  int errors_in_a_row_ = 0;

  std::thread thread_; // last: starts once everything above exists
};

void LibusbTransport::run() {
  link_.waiting("not connected");
  while (!stop_) {
    if (!ctx_ && !init_context()) {
      // No libusb at all (not installed, no usbfs, a sandbox): try again later.
      for (auto until = Clock::now() + config_.rescan_interval; !stop_ && Clock::now() < until;) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      continue;
    }
    {
      // Scoped: these references must be gone before a rescan drops the
      // context they belong to.
      const std::vector<DevicePtr> arrivals = std::move(arrivals_);
      arrivals_.clear();
      for (const DevicePtr &dev : arrivals) {
        if (!handle_) {
          try_open(dev.get());
        }
      }
    }
    if (!handle_ && Clock::now() >= next_rescan_) {
      // A fresh enumeration. With hotplug, that means a fresh context:
      // libusb's device list only changes on hotplug events, and on a system
      // without udevd those never come.
      if (hotplug_) {
        drop_context();
        if (!init_context()) {
          continue;
        }
      } else {
        scan_device_list();
      }
      next_rescan_ = Clock::now() + config_.rescan_interval;
      continue; // open what the scan found before waiting for events
    }
    timeval slice{0, kEventSliceUs};
    libusb().handle_events_timeout_completed(ctx_.get(), &slice, nullptr);

    if (handle_ && halted_ && !gone_) {
      // A stalled endpoint: clear it here, outside the transfer callback
      // (a synchronous request inside one would re-enter the event loop).
      const int rc = libusb().clear_halt(handle_.get(), lens_.endpoint);
      halted_ = false;
      if (rc < 0) {
        mark_gone("clear halt on endpoint failed: " + error_name(rc));
      } else {
        for (Slot &slot : slots_) {
          if (!slot.in_flight && !gone_) {
            submit(slot);
          }
        }
      }
    }
    if (handle_ && gone_) {
      close_device(gone_reason_);
      next_rescan_ = Clock::now(); // it may be back already (a transient error)
    }
  }
  if (handle_) {
    close_device("stopped");
  }
  drop_context();
}

bool LibusbTransport::init_context() {
  if (const std::string &error = libusb_load_error(); !error.empty()) {
    link_.waiting(error);
    return false;
  }
  libusb_context *raw = nullptr;
  if (const int rc = libusb().init(&raw); rc < 0) {
    link_.waiting("libusb_init failed: " + error_name(rc));
    return false;
  }
  ctx_.reset(raw);
  hotplug_ = libusb().has_capability(LIBUSB_CAP_HAS_HOTPLUG) != 0;
  if (hotplug_) {
    // ENUMERATE: the boards already present arrive through the same callback.
    const int rc = libusb().hotplug_register_callback(
        ctx_.get(),
        static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED |
                                          LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
        LIBUSB_HOTPLUG_ENUMERATE, config_.vid, config_.pid, LIBUSB_HOTPLUG_MATCH_ANY,
        hotplug_callback, this, &hotplug_handle_);
    hotplug_ = rc == LIBUSB_SUCCESS;
  }
  if (!hotplug_) {
    scan_device_list();
  }
  next_rescan_ = Clock::now() + config_.rescan_interval;
  return true;
}

void LibusbTransport::drop_context() {
  arrivals_.clear(); // device references die before their context
  if (ctx_ && hotplug_) {
    libusb().hotplug_deregister_callback(ctx_.get(), hotplug_handle_);
  }
  hotplug_ = false;
  ctx_.reset();
}

void LibusbTransport::scan_device_list() {
  const DeviceList list(ctx_.get());
  if (list.count() < 0) {
    link_.waiting("libusb_get_device_list failed: " + error_name(static_cast<int>(list.count())));
    return;
  }
  for (ssize_t i = 0; i < list.count(); ++i) {
    libusb_device_descriptor desc{};
    if (libusb().get_device_descriptor(list[i], &desc) == LIBUSB_SUCCESS &&
        desc.idVendor == config_.vid && desc.idProduct == config_.pid) {
      arrivals_.emplace_back(libusb().ref_device(list[i]));
    }
  }
}

void LibusbTransport::try_open(libusb_device *dev) {
  libusb_device_descriptor desc{};
  if (libusb().get_device_descriptor(dev, &desc) != LIBUSB_SUCCESS ||
      desc.idVendor != config_.vid || desc.idProduct != config_.pid) {
    return;
  }
  libusb_device_handle *raw = nullptr;
  if (const int rc = libusb().open(dev, &raw); rc < 0) {
    std::string why = "cannot open " + where(dev) + ": " + error_name(rc);
    if (rc == LIBUSB_ERROR_ACCESS) {
      why += " (no permission on /dev/bus/usb: install systemd/70-camhead-lens.rules)";
    }
    link_.waiting(why);
    return;
  }
  HandlePtr handle(raw);

  const std::string serial = read_serial(handle.get(), desc);
  if (config_.serial && serial != *config_.serial) {
    link_.waiting("found " + where(dev) + " with serial \"" + serial + "\", not ours");
    return;
  }

  libusb_config_descriptor *config_raw = nullptr;
  if (const int rc = libusb().get_active_config_descriptor(dev, &config_raw); rc < 0) {
    link_.waiting("cannot read the configuration of " + where(dev) + ": " + error_name(rc));
    return;
  }
  const ConfigPtr config(config_raw);
  const std::optional<LensInterface> lens = find_lens_interface(*config);
  if (!lens || lens->max_packet == 0) {
    char ids[16];
    std::snprintf(ids, sizeof ids, "%02x/%02x/%02x", kUsbLensInterfaceClass,
                  kUsbLensInterfaceSubClass, kUsbLensInterfaceProtocol);
    link_.waiting(where(dev) + " has no lens interface (class " + ids + ")");
    return;
  }
  // A vendor interface has no kernel driver; detaching one (usbfs from
  // another program aside) is harmless where the platform cannot.
  libusb().set_auto_detach_kernel_driver(handle.get(), 1);
  if (const int rc = libusb().claim_interface(handle.get(), lens->number); rc < 0) {
    link_.waiting("cannot claim interface " + std::to_string(lens->number) + " of " + where(dev) +
                  ": " + error_name(rc) +
                  (rc == LIBUSB_ERROR_BUSY ? " (another program has it)" : ""));
    return;
  }

  std::string description = where(dev);
  if (!serial.empty()) {
    description += ", serial " + serial;
  }
  description += ", " + read_board_info(handle.get(), lens->number);

  handle_ = std::move(handle);
  lens_ = *lens;
  gone_ = halted_ = false;
  gone_reason_.clear();
  errors_in_a_row_ = 0;
  link_.device_arrived(description);

  // One packet per transfer: a report is one short packet, which ends it.
  const std::size_t size = std::max<std::size_t>(lens_.max_packet, kUsbLensReportSize);
  for (Slot &slot : slots_) {
    if (!slot.transfer) {
      slot.transfer.reset(libusb().alloc_transfer(0));
    }
    slot.buffer.assign(size, 0);
    if (lens_.interrupt) {
      libusb_fill_interrupt_transfer(slot.transfer.get(), handle_.get(), lens_.endpoint,
                                     slot.buffer.data(), static_cast<int>(size), transfer_callback,
                                     this, 0);
    } else {
      libusb_fill_bulk_transfer(slot.transfer.get(), handle_.get(), lens_.endpoint,
                                slot.buffer.data(), static_cast<int>(size), transfer_callback, this,
                                0);
    }
    if (!gone_) {
      submit(slot);
    }
  }
}

void LibusbTransport::submit(Slot &slot) {
  const int rc = libusb().submit_transfer(slot.transfer.get());
  if (rc == LIBUSB_SUCCESS) {
    slot.in_flight = true;
  } else if (rc == LIBUSB_ERROR_NO_DEVICE) {
    mark_gone("device went away (LIBUSB_ERROR_NO_DEVICE)");
  } else {
    mark_gone("cannot submit a transfer: " + error_name(rc));
  }
}

void LibusbTransport::mark_gone(std::string reason) {
  if (!gone_) {
    gone_ = true;
    gone_reason_ = std::move(reason);
  }
}

void LibusbTransport::on_transfer(libusb_transfer *transfer) {
  Slot *slot = nullptr;
  for (Slot &s : slots_) {
    if (s.transfer.get() == transfer) {
      slot = &s;
    }
  }
  if (slot == nullptr) {
    return;
  }
  slot->in_flight = false;
  switch (transfer->status) {
  case LIBUSB_TRANSFER_COMPLETED:
    errors_in_a_row_ = 0;
    link_.report_received(std::span<const std::uint8_t>(
                              transfer->buffer, static_cast<std::size_t>(transfer->actual_length)),
                          monotonic_ns());
    break;
  case LIBUSB_TRANSFER_OVERFLOW:
    link_.report_rejected("usb lens report: longer than " + std::to_string(slot->buffer.size()) +
                          " bytes (" + transfer_status_name(transfer->status) + ")");
    break;
  case LIBUSB_TRANSFER_NO_DEVICE:
    mark_gone(std::string{"device went away ("} + transfer_status_name(transfer->status) + ")");
    return;
  case LIBUSB_TRANSFER_CANCELLED:
    return; // closing
  case LIBUSB_TRANSFER_STALL:
    halted_ = true; // cleared by the event loop, which then resubmits
    return;
  case LIBUSB_TRANSFER_ERROR:
  case LIBUSB_TRANSFER_TIMED_OUT:
    if (++errors_in_a_row_ >= kMaxErrorsInARow) {
      mark_gone(std::to_string(errors_in_a_row_) + " transfer errors in a row (" +
                transfer_status_name(transfer->status) + ")");
      return;
    }
    break;
  }
  if (!gone_ && !halted_) {
    submit(*slot);
  }
}

void LibusbTransport::close_device(const std::string &reason) {
  // No completion resubmits from here on. A transfer that completed just
  // before its cancellation would otherwise go out again, uncancelled, be
  // waited for in vain and abandoned below: a stop while the board streamed
  // took 2 s and leaked it (LeakSanitizer, the hardware lab's replug loop).
  gone_ = true;
  for (Slot &slot : slots_) {
    if (slot.in_flight) {
      libusb().cancel_transfer(slot.transfer.get());
    }
  }
  const auto deadline = Clock::now() + kCancelWait;
  const auto any_in_flight = [this] {
    return std::any_of(slots_.begin(), slots_.end(), [](const Slot &s) { return s.in_flight; });
  };
  while (any_in_flight() && Clock::now() < deadline) {
    timeval slice{0, 10'000};
    libusb().handle_events_timeout_completed(ctx_.get(), &slice, nullptr);
  }
  std::string why = reason;
  for (Slot &slot : slots_) {
    if (slot.in_flight) {
      // libusb still owns it: freeing it would be a use-after-free.
      (void)slot.transfer.release();
      slot.in_flight = false;
      why += " (a transfer did not return from cancellation)";
    } else {
      // Freed now, not kept for the next device: a transfer that has been
      // submitted holds a reference to its device (libusb >= 1.0.26) until it
      // is freed or submitted again, and the next device may come in a fresh
      // context, after drop_context() has exited this one. Dropping that
      // reference then would touch the freed context (a crash after a
      // replug). It also points at handle_, which is about to be closed.
      slot.transfer.reset();
    }
  }
  libusb().release_interface(handle_.get(), lens_.number);
  handle_.reset();
  gone_ = halted_ = false;
  link_.device_left(why);
}

} // namespace
} // namespace detail

std::unique_ptr<LensEncoder> open_usb_lens(const UsbLensConfig &config) {
  return std::make_unique<detail::UsbLensEncoder>(
      usb_lens_name(config), config,
      [&config](UsbLensLink &link) -> std::unique_ptr<detail::UsbLensTransport> {
        return std::make_unique<detail::LibusbTransport>(config, link);
      });
}

} // namespace camhead::hal::lens
