// The board's lens chain on its own thread: every source polled into its
// tracker, and the lens state at any instant for the frames that ask. The
// first source of the board is the lens of the frames (a rig has one lens;
// more sources are for monitoring and fallback, which is to come). Where the
// board's pose comes from a tracker (a FreeD or OpenTrackIO source), its
// poses are kept too, and the pose at any instant asked for alike.
//
// Thread safety: state_at() from any thread, while the hub runs.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "camhead/lens_control/lens_profile.h"
#include "camhead/lens_control/lens_state.h"
#include "config/lens_sources.h"

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

struct PoseSnapshot {
  CameraPose pose;
  // The tracker is there and its pose current at that instant; a static
  // pose always is.
  bool fresh = false;
  // False for an instant before the source's first pose: `pose` is the
  // scene's camera, a stand-in, and the frame goes out as the camera image
  // alone.
  bool known = false;
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
  // The same once the readings that cover t_ns have come. A source hands
  // its readings over a little after they happen (its own delay, the lens
  // thread's poll), and a run's first frame can come before the first of
  // them: then the state is the profile's rest state or an extrapolation,
  // a lens the rig never had. Waits (polling each millisecond) while they
  // can still come (LensSnapshot::awaited: not for a lost source, nor for
  // an instant before its history or inside a dropout, which no wait
  // mends), until CLOCK_MONOTONIC `give_up_ns` or `*stop`. The renderer and
  // the marker tracker both see a frame through its lens this way.
  [[nodiscard]] LensSnapshot state_when_covered(std::int64_t t_ns, std::int64_t give_up_ns,
                                                const std::atomic<bool> *stop = nullptr) const;
  // Whether the board's pose comes from a tracker.
  [[nodiscard]] bool tracks_pose() const { return pose_channel_.has_value(); }
  // The tracker's pose at CLOCK_MONOTONIC instant t_ns; `rest` (not fresh)
  // before its first pose, or `rest` (fresh) for a board that tracks none.
  [[nodiscard]] PoseSnapshot pose_at(std::int64_t t_ns, const CameraPose &rest) const;
  // "static", or the tracker's type and lens source ("freed:tracker"), for
  // the record and the status line.
  [[nodiscard]] const std::string &pose_source() const { return pose_source_; }

  // Every source's readings mapped through `profile` from the next state_at()
  // on (a reload): the history stays, so no frame loses its lens.
  void set_profile(const lens_control::LensProfile &profile);

  // The lens source's newest reading as it came (encoder counts, or the
  // values a calibrated source sends), for calibration marks.
  [[nodiscard]] std::optional<hal::lens::EncoderReading> last_reading() const;

  // "focus pull [trace ...]" for the status line.
  [[nodiscard]] std::string source_name() const;

private:
  void poll_loop();
  // Polls every source once, waiting up to `timeout` on each.
  void poll_all(std::chrono::milliseconds timeout);

  // Guards the channels' trackers (feed, state_at) and the status reads; the
  // sources themselves are polled by the lens thread alone.
  mutable std::mutex mutex_;
  std::vector<LensChannel> channels_;
  std::vector<bool> connected_;             // each source's status().connected after its last poll
  std::optional<std::size_t> pose_channel_; // the channel whose poses are the camera's
  std::string pose_source_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> polled_{false}; // every source polled once
  std::thread thread_;
};

} // namespace camhead::pipeline
