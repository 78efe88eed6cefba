// See setup_reloader.h.
#include "setup_reloader.h"

#include <chrono>
#include <exception>
#include <thread>
#include <utility>

#include "board_reload.h"
#include "camhead/base/monotonic_clock.h"
#include "config/lens_sources.h"

namespace camhead::pipeline {

SetupReloader::SetupReloader(std::atomic<bool> &requested, const ServiceNotifier *service,
                             SetupHandover &handover, LensHub &lens,
                             std::function<std::unique_ptr<FrameSetup>(const Board &)> build,
                             std::function<bool()> stop)
    : requested_(requested), service_(service), handover_(handover), lens_(lens),
      build_(std::move(build)), stop_(std::move(stop)) {}

std::string SetupReloader::reload(Board &live) {
  try {
    // Everything is read, checked and made beside the running setup; the
    // render thread only swaps it in between two frames.
    Board board = reread_board(live);
    lens_control::LensProfile profile = load_board_profile(board);
    std::unique_ptr<FrameSetup> next = build_(board);
    const std::uint64_t generation = reloads_ + 1;
    next->generation = generation;
    bool taken = false;
    // Freed here, not in the render thread: the setup it replaced (or this
    // one, when the run ended first).
    std::unique_ptr<FrameSetup> spent = handover_.offer(std::move(next), stop_, taken);
    if (!taken)
      return {};
    lens_.set_profile(profile);
    live = std::move(board);
    ++reloads_;
    return "reloaded " + live.file.string() + ": setup " + std::to_string(generation);
  } catch (const std::exception &e) {
    ++refused_;
    return std::string("reload refused, the run goes on as it was: ") + e.what();
  }
}

void SetupReloader::run(Board live) {
  while (!stop_()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (!requested_.exchange(false))
      continue;
    if (service_ != nullptr)
      (void)service_->notify("RELOADING=1\nMONOTONIC_USEC=" +
                             std::to_string(base::monotonic_ns() / 1000));
    std::string note = reload(live);
    if (note.empty())
      break; // the run ended first
    if (service_ != nullptr)
      (void)service_->notify("READY=1\nSTATUS=" + note);
    const std::lock_guard lock(mutex_);
    last_ = {last_.count + 1, note};
    note_ = std::move(note);
  }
}

std::optional<std::string> SetupReloader::take_note() {
  const std::lock_guard lock(mutex_);
  return std::exchange(note_, std::nullopt);
}

SetupReloader::Outcome SetupReloader::last_outcome() {
  const std::lock_guard lock(mutex_);
  return last_;
}

} // namespace camhead::pipeline
