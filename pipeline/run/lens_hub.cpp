#include "lens_hub.h"

#include <chrono>
#include <cmath>
#include <optional>

#include "camhead/base/monotonic_clock.h"
#include "camhead/base/thread_name.h"

namespace camhead::pipeline {

LensHub::LensHub(const Board &board)
    : channels_(open_lens_channels(board)), connected_(channels_.size(), false),
      pose_source_("static") {
  if (!board.pose || !pose_from_lens_source(board.pose->type))
    return;
  for (std::size_t i = 0; i < channels_.size(); ++i)
    if (channels_[i].config().name == board.pose->source) {
      channels_[i].track_pose(board.pose->type, board.pose->delay_ms);
      pose_channel_ = i;
    }
  pose_source_ = std::string(pose_type_name(board.pose->type)) + ":" + board.pose->source;
}

void LensHub::start() {
  if (thread_.joinable())
    return;
  // The first poll here, on the caller's thread: a trace played from the
  // rig's start starts its clock at its first poll, and it must not start
  // after a camera thread has exposed a frame (under load the lens thread's
  // first poll can come late, and a frame before a trace's first reading
  // has no lens state that any wait could give it).
  poll_all(std::chrono::milliseconds(0));
  thread_ = std::thread([this] {
    base::name_this_thread("camhead-lens");
    poll_loop();
  });
}

LensHub::~LensHub() {
  stop_ = true;
  if (thread_.joinable())
    thread_.join();
}

void LensHub::poll_loop() {
  using namespace std::chrono_literals;
  while (!stop_)
    poll_all(channels_.size() == 1 ? 5ms : 1ms);
}

void LensHub::poll_all(std::chrono::milliseconds timeout) {
  // The waiting happens outside the lock; a frame asking for its lens
  // state waits only for the readings to be handed to the tracker.
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    LensChannel &channel = channels_[i];
    channel.poll(timeout);
    // A source's status is read here, on the thread that polls it.
    const bool connected = channel.encoder().status().connected;
    std::lock_guard lock(mutex_);
    channel.feed();
    connected_[i] = connected;
  }
  polled_ = true;
}

LensSnapshot LensHub::state_at(std::int64_t t_ns) const {
  std::lock_guard lock(mutex_);
  LensSnapshot snapshot;
  const LensChannel &lens = channels_.front();
  snapshot.state = lens.state_at(t_ns);
  snapshot.connected = connected_.front();
  snapshot.fresh = snapshot.connected && snapshot.state.all_fresh();
  // The newest reading, moved to physical time by the source's delay.
  const std::optional<hal::lens::EncoderReading> &last = lens.last_reading();
  const auto delay_ns = std::llround(lens.config().delay_ms * 1e6);
  snapshot.awaited = (snapshot.connected || !polled_) && (!last || last->t_ns - delay_ns < t_ns);
  return snapshot;
}

std::optional<hal::lens::EncoderReading> LensHub::last_reading() const {
  std::lock_guard lock(mutex_);
  return channels_.front().last_reading();
}

LensSnapshot LensHub::state_when_covered(std::int64_t t_ns, std::int64_t give_up_ns,
                                         const std::atomic<bool> *stop) const {
  LensSnapshot lens = state_at(t_ns);
  while (!lens.fresh && lens.awaited && !(stop != nullptr && *stop) &&
         base::monotonic_ns() < give_up_ns) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    lens = state_at(t_ns);
  }
  return lens;
}

PoseSnapshot LensHub::pose_at(std::int64_t t_ns, const CameraPose &rest) const {
  if (!pose_channel_)
    return {rest, true, true}; // a static pose
  std::lock_guard lock(mutex_);
  const std::optional<PoseAt> at = channels_[*pose_channel_].pose_at(t_ns);
  if (!at || at->before_first)
    return {rest, false, false};
  return {at->pose, at->fresh && connected_[*pose_channel_], true};
}

void LensHub::set_profile(const lens_control::LensProfile &profile) {
  // Copied before the lock: a frame waiting for its lens waits on it.
  std::vector<lens_control::LensProfile> copies(channels_.size(), profile);
  std::lock_guard lock(mutex_);
  for (std::size_t i = 0; i < channels_.size(); ++i)
    channels_[i].set_profile(std::move(copies[i]));
}

std::string LensHub::source_name() const {
  std::lock_guard lock(mutex_);
  const LensChannel &lens = channels_.front();
  return lens.config().name + " [" + lens.encoder().name() + "]";
}

} // namespace camhead::pipeline
