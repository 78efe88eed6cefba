// The reload thread of `camhead run` (RunOptions::reload, a service's
// SIGHUP): on each request the board is read anew and checked
// (board_reload.h), its setup built beside the running one and handed to
// the render thread (frame_setup.h, SetupHandover), and the lens profile
// swapped on the hub. systemd hears RELOADING=1, then READY=1 with the
// outcome as STATUS=; the status thread takes the outcome for its line.
//
// Thread safety: run() on the reload thread; request(), take_note(),
// last_outcome(), reloads() and refused() from any thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "config/board.h"
#include "frame_setup.h"
#include "lens_hub.h"
#include "service/service_notifier.h"

namespace camhead::pipeline {

class SetupReloader {
public:
  // `build` makes a board's setup with its renderer prepared (throws naming
  // the file or field at fault); `stop` says the run is over.
  SetupReloader(std::atomic<bool> &requested, const ServiceNotifier *service,
                SetupHandover &handover, LensHub &lens,
                std::function<std::unique_ptr<FrameSetup>(const Board &)> build,
                std::function<bool()> stop);

  // The thread's body: `live` is the board running.
  void run(Board live);
  // Asks for a reload, as the signal does (the operator page's button).
  void request() { requested_.store(true); }
  // The last outcome not yet taken ("reloaded FILE: setup N", "reload
  // refused, ...") for the status line.
  [[nodiscard]] std::optional<std::string> take_note();
  // The outcomes so far and the last one (empty before the first), for
  // the operator page: a count tells a new outcome from the same words.
  struct Outcome {
    std::uint64_t count = 0;
    std::string text;
  };
  [[nodiscard]] Outcome last_outcome();
  [[nodiscard]] std::uint64_t reloads() const { return reloads_; }
  [[nodiscard]] std::uint64_t refused() const { return refused_; }

private:
  // One reload: its outcome, or empty when the run ended before the render
  // thread took it.
  std::string reload(Board &live);

  std::atomic<bool> &requested_;
  const ServiceNotifier *service_;
  SetupHandover &handover_;
  LensHub &lens_;
  std::function<std::unique_ptr<FrameSetup>(const Board &)> build_;
  std::function<bool()> stop_;
  std::mutex mutex_;
  std::optional<std::string> note_;
  Outcome last_;
  std::atomic<std::uint64_t> reloads_{0}, refused_{0};
};

} // namespace camhead::pipeline
