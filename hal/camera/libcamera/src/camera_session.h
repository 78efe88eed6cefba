// One use of a libcamera camera, from acquire() to release(): its
// configuration, buffers (mmapped once), one Request per buffer, start and
// stop. The camera source (libcamera_source.cpp) makes one at open and one
// at each reconnect, and retires it when the camera goes away.
//
// Thread safety: create, start and stop from one thread (the capture
// thread); queue() from any, under the source's lock; bytes() is constant
// after creation.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <libcamera/camera.h>
#include <libcamera/framebuffer_allocator.h>
#include <libcamera/request.h>
#include <libcamera/stream.h>

#include "camhead/base/video_format.h"
#include "camhead/hal/camera/libcamera/libcamera_camera.h"

namespace camhead::hal::camera {

class CameraSession {
public:
  // Acquires and configures `camera` as `options` say, allocates and maps
  // its buffers and makes their Requests, with cookies `cookie_base | i`;
  // null with `error` ("CAMERA: REASON") where any step fails, the camera
  // then released again. `label` names the camera in messages.
  [[nodiscard]] static std::unique_ptr<CameraSession>
  create(std::shared_ptr<libcamera::Camera> camera, const std::string &label,
         const LibcameraCameraOptions &options, std::uint64_t cookie_base, std::string &error);

  ~CameraSession();
  CameraSession(const CameraSession &) = delete;
  CameraSession &operator=(const CameraSession &) = delete;

  // Starts the camera and queues every Request; "" or why not.
  [[nodiscard]] std::string start();
  // Stops the camera: every queued Request completes (cancelled) before it
  // returns. False for a disconnected camera, which libcamera 0.0.3 cannot
  // stop; its Requests are then abandoned (camera_session.cpp says why that
  // is safe). The destructor stops a running camera too.
  bool stop();

  // Reuses Request `index` and queues it again; "" or why not.
  [[nodiscard]] std::string queue(int index);

  [[nodiscard]] libcamera::Camera &camera() const { return *camera_; }
  [[nodiscard]] const libcamera::Stream *stream() const { return stream_; }
  [[nodiscard]] const base::VideoFormat &format() const { return format_; }
  [[nodiscard]] int buffers() const { return static_cast<int>(requests_.size()); }
  [[nodiscard]] std::span<const std::uint8_t> bytes(int index) const;
  // "480x360 RGB888 (camhead bgr24), stride 1440, 4 buffers" for status lines.
  [[nodiscard]] const std::string &summary() const { return summary_; }

private:
  struct Mapping {
    void *base = nullptr;
    std::size_t length = 0;
    std::size_t frame_offset = 0;
  };

  CameraSession() = default;

  std::shared_ptr<libcamera::Camera> camera_;
  bool acquired_ = false;
  bool running_ = false;
  std::unique_ptr<libcamera::CameraConfiguration> config_;
  libcamera::Stream *stream_ = nullptr;
  std::unique_ptr<libcamera::FrameBufferAllocator> allocator_;
  std::vector<std::unique_ptr<libcamera::Request>> requests_;
  std::vector<Mapping> mappings_;
  base::VideoFormat format_;
  std::string summary_;
};

} // namespace camhead::hal::camera
