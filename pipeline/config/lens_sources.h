// From a board's lens sources to lens states: opens each source's hal/
// backend (or its simulated twin) and feeds what it reads into its own
// lens_control::LensTracker. This is the one place where hal's raw readings
// become lens_control's samples (architecture.md: pipeline translates).
//
// Thread safety: none. The lens thread owns the channels.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "camhead/hal/lens/lens_encoder.h"
#include "camhead/lens_control/lens_profile.h"
#include "camhead/lens_control/lens_state.h"
#include "camhead/lens_control/lens_tracker.h"
#include "config/board.h"
#include "tracking/pose_timeline.h"

namespace camhead::pipeline {

// Opens the backend a board source names. Network sources bind here and
// throw std::runtime_error naming the source when they cannot; USB and GPIO
// sources without their device open anyway and report "not connected" in
// their status (the rig must start without them). A source with `simulate`
// set runs the backend's simulated twin, driven by that trace, through the
// same code above the device.
[[nodiscard]] std::unique_ptr<hal::lens::LensEncoder>
open_lens_source(const LensSourceConfig &source);

// hal's reading as lens_control's sample: counts, which lens_control maps
// through the profile, and the calibrated values the source sent
// (lens_tracker.h says which of the two an axis takes).
[[nodiscard]] lens_control::EncoderSample to_encoder_sample(const hal::lens::EncoderReading &r);

// The board's profile, or the flagged uncalibrated fallback when it names
// none. Throws lens_control::ProfileError naming the file.
[[nodiscard]] lens_control::LensProfile load_board_profile(const Board &board);

// One source and the tracker it feeds.
class LensChannel {
public:
  LensChannel(LensSourceConfig config, std::unique_ptr<hal::lens::LensEncoder> encoder,
              const lens_control::LensProfile &profile);

  // Polls the source once (at most `timeout`) and feeds every reading to the
  // tracker. Returns how many readings arrived.
  std::size_t pump(std::chrono::milliseconds timeout);
  // pump() in two halves, for a thread that shares the tracker with others:
  // poll() waits on the source and touches only this channel's own batch,
  // so it can run outside a lock; feed() hands the batch to the tracker.
  std::size_t poll(std::chrono::milliseconds timeout);
  void feed();

  [[nodiscard]] const LensSourceConfig &config() const { return config_; }
  [[nodiscard]] const hal::lens::LensEncoder &encoder() const { return *encoder_; }
  [[nodiscard]] const std::optional<hal::lens::EncoderReading> &last_reading() const {
    return last_;
  }
  [[nodiscard]] lens_control::LensState state_at(std::int64_t t_ns) const {
    return tracker_.state_at(t_ns);
  }
  // A reloaded profile; the readings so far are kept (LensTracker::set_profile).
  void set_profile(lens_control::LensProfile profile) { tracker_.set_profile(std::move(profile)); }

  // Keeps the camera poses the source sends from now on (a FreeD or
  // OpenTrackIO tracker's, in that protocol's axes: `type`), moved back by
  // `delay_ms`, in camhead's world.
  void track_pose(PoseType type, double delay_ms);
  // The pose at physical instant t_ns (PoseTimeline::at); empty before the
  // first one arrived, or when the channel does not track poses.
  [[nodiscard]] std::optional<PoseAt> pose_at(std::int64_t t_ns) const {
    return poses_ ? poses_->at(t_ns) : std::nullopt;
  }

private:
  LensSourceConfig config_;
  std::unique_ptr<hal::lens::LensEncoder> encoder_;
  lens_control::LensTracker tracker_;
  PoseType pose_type_ = PoseType::fixed;
  std::optional<PoseTimeline> poses_;
  std::optional<hal::lens::EncoderReading> last_;
  std::vector<hal::lens::EncoderReading> batch_;
};

// Every source of the board, each on the board's profile.
[[nodiscard]] std::vector<LensChannel> open_lens_channels(const Board &board);
// The same with the board's profile already loaded (load_board_profile()).
[[nodiscard]] std::vector<LensChannel> open_lens_channels(const Board &board,
                                                          const lens_control::LensProfile &profile);

} // namespace camhead::pipeline
