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
  // The readings that would cover that instant may still come: the source
  // is delivering (or not yet polled) and has no reading at or after it.
  // Not so for an instant before its history or inside a dropout.
  bool awaited = false;
};

class LensHub {
public:
  // Opens the board's sources (throws as open_lens_channels does).
  explicit LensHub(const Board &board);
  // Starts polling them, once; a trace played from the rig's start starts
  // here, so that a run starts it once everything else stands.
  void start();
  ~LensHub();
  LensHub(const LensHub &) = delete;
  LensHub &operator=(const LensHub &) = delete;

  // The lens at CLOCK_MONOTONIC instant t_ns: a lost source holds its last
  // state, flagged not fresh.
  [[nodiscard]] LensSnapshot state_at(std::int64_t t_ns) const;
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
  std::atomic<bool> polled_{false}; // every source polled once
  std::thread thread_;
};

} // namespace camhead::pipeline
