// What every output backend does around its own writing, written once: a
// frame is refused after close() or at the wrong size, frames and failures
// are counted, the status (read from any thread) is kept under a lock, and
// close() runs once. A backend writes a frame in send(), finishes in
// finish(), and says what happened with ready(), fail(), away() and say().
//
// The states a sink goes through, and who moves it:
//   connected  ready() at open or when a lost device is back; send() works
//   away       away(): the device is gone or dark, frames are skipped (not
//              errors) while the backend looks for it again
//   broken     writable() false: fail() leaves it disconnected (a file a
//              failed write could not undo, a device closed on its loss)
//   closed     close(): finish() ran; every later call is an error
#pragma once

#include <cstdint>
#include <mutex>
#include <span>
#include <string>

#include "camhead/hal/output/frame_sink.h"

namespace camhead::hal::output {

class SinkBase : public FrameSink {
public:
  [[nodiscard]] base::VideoFormat format() const final { return format_; }

  bool submit(std::span<const std::uint8_t> frame, std::int64_t capture_ns) final {
    if (closed_)
      return fail("submit after close");
    if (std::string wrong = wrong_frame_size(frame, format_); !wrong.empty())
      return fail(wrong);
    if (!send(frame, capture_ns))
      return false; // send() said why
    const std::lock_guard lock(mutex_);
    ++status_.frames;
    return true;
  }

  bool close() final {
    if (closed_)
      return fail("closed twice");
    closed_ = true;
    return finish();
  }

  [[nodiscard]] SinkStatus status() const final {
    const std::lock_guard lock(mutex_);
    return status_;
  }

protected:
  explicit SinkBase(base::VideoFormat format) : format_(format) {}

  // Sends one frame of the right size; false after fail() or away().
  virtual bool send(std::span<const std::uint8_t> frame, std::int64_t capture_ns) = 0;
  // Completes the output, once; true after closed(), false after fail().
  virtual bool finish() = 0;
  // Whether frames can still go out once a submission failed.
  [[nodiscard]] virtual bool writable() const { return true; }

  // Working: `detail` is the state ("ready, ...", "back, ...").
  void ready(const std::string &detail) { set(true, detail); }
  // A frame (or the close) failed: counted as an error.
  bool fail(const std::string &reason) {
    const std::lock_guard lock(mutex_);
    ++status_.errors;
    status_.detail = name() + ": " + reason;
    status_.connected = !closed_ && writable();
    return false;
  }
  // The device is away: frames are skipped, not counted as errors.
  bool away(const std::string &why) {
    set(false, why);
    return false;
  }
  // Closed as it should be: `detail` says what was left behind.
  bool closed(const std::string &detail) {
    set(false, detail);
    return true;
  }
  // A note on the state that changes nothing else.
  void say(const std::string &detail) {
    const std::lock_guard lock(mutex_);
    status_.detail = name() + ": " + detail;
  }
  [[nodiscard]] std::uint64_t frames() const { return status().frames; }

private:
  void set(bool connected, const std::string &detail) {
    const std::lock_guard lock(mutex_);
    status_.connected = connected;
    status_.detail = name() + ": " + detail;
  }

  const base::VideoFormat format_;
  bool closed_ = false; // the submitting thread's

  mutable std::mutex mutex_; // guards status_
  SinkStatus status_;
};

} // namespace camhead::hal::output
