#include "lens_hub.h"

#include <chrono>

namespace camhead::pipeline {

LensHub::LensHub(const Board &board) : channels_(open_lens_channels(board)) {
  thread_ = std::thread([this] { poll_loop(); });
}

LensHub::~LensHub() {
  stop_ = true;
  thread_.join();
}

void LensHub::poll_loop() {
  using namespace std::chrono_literals;
  while (!stop_) {
    {
      // Short polls keep a frame's wait for the lock under a millisecond;
      // the sources queue what arrives meanwhile.
      std::lock_guard lock(mutex_);
      for (LensChannel &channel : channels_)
        channel.pump(1ms);
    }
    std::this_thread::yield(); // let a waiting frame take the lock
  }
}

LensSnapshot LensHub::state_at(std::int64_t t_ns) const {
  std::lock_guard lock(mutex_);
  LensSnapshot snapshot;
  const LensChannel &lens = channels_.front();
  snapshot.state = lens.state_at(t_ns);
  snapshot.connected = lens.encoder().status().connected;
  snapshot.fresh = snapshot.connected && snapshot.state.all_fresh();
  return snapshot;
}

std::string LensHub::source_name() const {
  std::lock_guard lock(mutex_);
  const LensChannel &lens = channels_.front();
  return lens.config().name + " [" + lens.encoder().name() + "]";
}

} // namespace camhead::pipeline
