// A delivered camera frame as a value that gives its buffer back by itself:
// move-only, it calls CameraSource::release() once, when its holder lets go
// (destroyed, reset, or assigned another frame), on whatever thread that
// is, as release() allows. A frame dropped on any path (replaced in a
// queue, refused, without an output slot, rendered) so never keeps a
// buffer from the camera, and none is given back twice (rpicam-apps'
// CompletedRequest, libcamera's Request reuse).
//
// The source must outlive its leases.
#pragma once

#include <utility>

#include "camhead/hal/camera/camera_source.h"

namespace camhead::hal::camera {

class FrameLease {
public:
  FrameLease() = default;
  // Takes a frame that `source` delivered through wait_frame().
  FrameLease(CameraSource &source, const CapturedFrame &frame) : source_(&source), frame_(frame) {}
  ~FrameLease() { reset(); }

  FrameLease(FrameLease &&other) noexcept
      : source_(std::exchange(other.source_, nullptr)), frame_(other.frame_) {}
  FrameLease &operator=(FrameLease &&other) noexcept {
    if (this != &other) {
      reset();
      source_ = std::exchange(other.source_, nullptr);
      frame_ = other.frame_;
    }
    return *this;
  }
  FrameLease(const FrameLease &) = delete;
  FrameLease &operator=(const FrameLease &) = delete;

  // Whether it holds a frame.
  [[nodiscard]] explicit operator bool() const { return source_ != nullptr; }
  // The frame; its bytes are valid while the lease holds it.
  [[nodiscard]] const CapturedFrame &frame() const { return frame_; }

  // Gives the buffer back now (nothing if it holds none).
  void reset() {
    if (CameraSource *source = std::exchange(source_, nullptr))
      source->release(frame_);
  }

private:
  CameraSource *source_ = nullptr;
  CapturedFrame frame_;
};

} // namespace camhead::hal::camera
