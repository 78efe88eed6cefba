// The board's lens chain on its own thread: every source polled into its
// tracker, and the lens state at any instant for the frames that ask. The
// first source of the board is the lens of the frames (a rig has one lens;
// more sources are for monitoring and fallback, which is to come).
//
// Thread safety: state_at() from any thread, while the hub runs.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "camhead/lens_control/lens_state.h"
#include "lens_sources.h"

namespace camhead::pipeline {

struct LensSnapshot {
  lens_control::LensState state;
  bool connected = false; // the source is there and delivering
  bool fresh = false;     // connected and every axis current at that instant
};

class LensHub {
public:
  // Opens the board's sources (throws as open_lens_channels does) and starts
  // polling them.
  explicit LensHub(const Board &board);
  ~LensHub();
  LensHub(const LensHub &) = delete;
  LensHub &operator=(const LensHub &) = delete;

  // The lens at CLOCK_MONOTONIC instant t_ns: a lost source holds its last
  // state, flagged not fresh.
  [[nodiscard]] LensSnapshot state_at(std::int64_t t_ns) const;
  // Whether every source has been polled once, and what it had handed to
  // its tracker (a frame before that finds no reading that is not yet
  // there).
  [[nodiscard]] bool started() const { return started_; }
  // "focus pull [trace ...]" for the status line.
  [[nodiscard]] std::string source_name() const;

private:
  void poll_loop();

  // Guards the channels' trackers (feed, state_at) and the status reads; the
  // sources themselves are polled by the lens thread alone.
  mutable std::mutex mutex_;
  std::vector<LensChannel> channels_;
  std::vector<bool> connected_; // each source's status().connected after its last poll
  std::atomic<bool> stop_{false};
  std::atomic<bool> started_{false};
  std::thread thread_;
};

} // namespace camhead::pipeline
